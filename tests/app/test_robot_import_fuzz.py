"""The importer fuzzed (hypothesis): descriptions that gaitbot wrote itself (the op3 and ax12a-biped as URDF,
the op3 as MJCF), broken by random edits (lines dropped, doubled or swapped, numbers replaced by extreme or
unreadable ones, the file cut short, text inserted). ``gaitbot robot import`` must take each in bounded time
and either write a config that loads or refuse it in one line, exit 2: never a traceback."""

from __future__ import annotations

import contextlib
import io
import re
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gaitbot.app.cli import main
from gaitbot.robot.config import load_robot_config, resolve_config
from gaitbot.robot.description.urdf_writer import urdf_text
from gaitbot.sim import SimUnavailable, import_mujoco


def _bases() -> dict[str, str]:
    op3, ax12a = (load_robot_config(resolve_config(n)) for n in ("op3", "ax12a-biped"))
    bases = {"op3.urdf": urdf_text(op3), "ax12a.urdf": urdf_text(ax12a)}
    try:
        import_mujoco()
        from gaitbot.sim.model3d import exported_mjcf

        bases["op3.xml"] = exported_mjcf(op3)
    except SimUnavailable:
        pass
    return bases


BASES = _bases()
NUMBER = re.compile(r"-?\d+(\.\d+)?(e-?\d+)?")
ODD_NUMBERS = ["0", "-1", "1e9", "-1e300", "nan", "inf", "", "x", "1e-12", "0.5 0.5", "3.3"]


@st.composite
def broken(draw):
    name = draw(st.sampled_from(sorted(BASES)))
    lines = BASES[name].splitlines()
    for _ in range(draw(st.integers(1, 4))):
        op = draw(st.sampled_from(["drop", "double", "swap", "number", "cut", "insert"]))
        i = draw(st.integers(0, len(lines) - 1))
        if op == "drop" and len(lines) > 1:
            del lines[i]
        elif op == "double":
            lines.insert(i, lines[i])
        elif op == "swap":
            j = draw(st.integers(0, len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
        elif op == "number":
            found = list(NUMBER.finditer(lines[i]))
            if found:
                m = found[draw(st.integers(0, len(found) - 1))]
                lines[i] = lines[i][:m.start()] + draw(st.sampled_from(ODD_NUMBERS)) + lines[i][m.end():]
        elif op == "cut":
            lines[i] = lines[i][:draw(st.integers(0, len(lines[i])))]
            del lines[i + 1:]
        else:
            lines.insert(i, draw(st.text(max_size=30)))
    return name, "\n".join(lines)


@pytest.mark.slow
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(broken())
def test_the_importer_writes_a_loadable_config_or_refuses_in_one_line(case):
    name, text = case
    with tempfile.TemporaryDirectory() as folder:
        path, out = Path(folder) / name, Path(folder) / "out.toml"
        path.write_text(text, encoding="utf-8", errors="surrogatepass")
        stdout, stderr = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
            code = main(["robot", "import", str(path), "--like", "op3", "-o", str(out)])
        err = stderr.getvalue()
        assert code in (0, 2), err
        assert "Traceback" not in err
        if code == 2:
            lines = [line for line in err.splitlines() if line.strip()]
            assert len(lines) == 1 and lines[0].startswith("gaitbot robot: error:"), err
            assert not out.exists()
        else:
            load_robot_config(out)


@pytest.mark.parametrize("name", sorted(BASES))
def test_the_unbroken_bases_import(name, tmp_path, capsys):
    path = tmp_path / name
    path.write_text(BASES[name])
    assert main(["robot", "import", str(path), "--like", "op3", "-o", str(tmp_path / "out.toml")]) == 0
