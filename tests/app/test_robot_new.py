"""``gaitbot robot new``: a complete commented template that plans, generates, checks and simulates as it is,
refused by the hardware commands until its placeholders are filled; and a config whose feet cannot stand
refused when it loads, naming the field."""

from __future__ import annotations

import re

import pytest

from helpers import REPO_ROOT, run_cli


def one_line_exit_2(result) -> str:
    code, out, err = result
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, (code, out, err)
    return err


@pytest.fixture(scope="module")
def templates(tmp_path_factory):
    from gaitbot.app.cli import main

    folder = tmp_path_factory.mktemp("new")
    out = {}
    for legs in (6, 12):
        out[legs] = folder / f"bot{legs}.toml"
        assert main(["robot", "new", f"bot{legs}", "--legs", str(legs), "-o", str(out[legs])]) == 0
    return out


@pytest.mark.parametrize("legs", [6, 12])
def test_the_template_loads_with_the_joints_asked_for(templates, legs):
    from gaitbot.gait.joints import LEG_JOINTS, PITCH_JOINTS
    from gaitbot.robot.config import load_robot_config

    config = load_robot_config(templates[legs])
    assert config.name == f"bot{legs}" and config.draft is not None
    assert set(config.joint_names) == set(PITCH_JOINTS if legs == 6 else LEG_JOINTS)
    assert config.is_3d == (legs == 12) and config.boom == (legs == 6)
    assert len({j.id for j in config.joints}) == legs  # one servo a joint


@pytest.mark.parametrize("legs", [6, 12])
def test_every_placeholder_is_marked(templates, legs):
    text = templates[legs].read_text()
    for key in ("id", "model", "zero_tick", "direction"):
        marked = re.findall(rf"^{key} = .*FILL IN", text, flags=re.M)
        assert len(marked) == legs, key
    for table in ("geometry", "mass", "bus"):
        assert re.search(rf"^\[{table}\].*FILL IN", text, flags=re.M), table


@pytest.mark.parametrize("legs", [6, 12])
def test_the_template_plans_generates_and_checks(capsys, templates, tmp_path, legs):
    walk = tmp_path / "walk.csv"
    assert run_cli(capsys, "plan", "--robot", templates[legs], "--distance", "0.3")[0] == 0
    code, out, err = run_cli(capsys, "generate", "--robot", templates[legs], "--distance", "0.3", "-o", walk)
    assert code == 0, err
    code, out, _ = run_cli(capsys, "check", walk)
    assert code == 0 and "OK (0 errors" in out, out
    code, out, err = run_cli(capsys, "walk", "--dry-run", "--robot", templates[legs], "--distance", "0.3")
    assert code == 0, err


@pytest.mark.slow
def test_the_12_joint_template_walks_in_the_simulation(capsys, templates):
    pytest.importorskip("mujoco")
    code, out, err = run_cli(capsys, "walk", "--sim", "--robot", templates[12], "--distance", "0.3")
    assert code == 0, out + err
    assert "free-floating" in out and "did not fall" in out


def test_the_hardware_refuses_the_template(capsys, templates):
    err = one_line_exit_2(run_cli(capsys, "walk", "--robot", templates[12], "--distance", "0.3"))
    assert "robot.draft" in err


@pytest.mark.parametrize("argv, words", [(["robot", "new", "bot", "--legs", "8", "-o", "x.toml"], "--legs"),
                                         (["robot", "new", "b o t", "--legs", "6", "-o", "x.toml"], "name"),
                                         (["robot", "new", "bot", "--legs", "6", "-o", "x.txt"], ".toml")])
def test_bad_arguments_are_one_line(capsys, tmp_path, monkeypatch, argv, words):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) if "8" in argv else _nothing():
        err = one_line_exit_2(run_cli(capsys, *argv))
        assert words in err
    assert not (tmp_path / "x.toml").exists()


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def _op3_with(tmp_path, old: str, new: str):
    text = (REPO_ROOT / "config" / "op3.toml").read_text()
    line = re.compile(rf"^{re.escape(old)}\b.*$", flags=re.M)
    assert line.search(text)
    path = tmp_path / "feet.toml"
    path.write_text(line.sub(new, text, count=1))
    return path


@pytest.mark.parametrize("old, new, field, words", [
    ("heel_back_m = 0.0635", "", "geometry.heel_back_m", "missing"),
    ("heel_back_m = 0.0635", "heel_back_m = 0.0", "geometry.heel_back_m", "too near the heel"),
    ("heel_back_m = 0.0635", "heel_back_m = 0.12", "geometry.heel_back_m", "too near the toe"),
    ("sole_outward_m = 0.0125", "sole_outward_m = 0.03", "geometry.sole_outward_m", "middle half"),
    ("foot_width_m = 0.078", "", "geometry.foot_width_m", "missing"),
])
def test_feet_that_cannot_stand_are_refused_at_load(capsys, tmp_path, old, new, field, words):
    bad = _op3_with(tmp_path, old, new)
    for argv in (["plan", "--robot", bad, "--distance", "0.3"],
                 ["generate", "--robot", bad, "--distance", "0.3", "-o", tmp_path / "w.csv"]):
        err = one_line_exit_2(run_cli(capsys, *argv))
        assert f"{bad}: {field}: " in err and words in err


def test_the_middle_half_holds_the_shipped_robots():
    """The bound is no tighter than the robots that walk: every shipped robot whose legs roll loads."""
    from gaitbot.robot.config import SOLE_MIDDLE, load_robot_config, resolve_config

    for name in ("op3", "bioloid"):
        g = load_robot_config(resolve_config(name)).geometry
        assert SOLE_MIDDLE[0] * g.foot_m <= g.heel_back_m <= SOLE_MIDDLE[1] * g.foot_m
