"""Property-based tests (hypothesis) of every reader of user input (issue 13, "the habit that keeps them
fixed"): robot configs, terrain courses, trajectory CSV and NPZ, bus recordings, eigen-gait models, and
the command line's arguments.

Each generated input is a mutation of a valid file (a field's value swapped for a hostile one, lines cut,
doubled or deleted, deep nesting, arrays of the wrong kind or shape) or a hostile argument. It is read in
a forked child with an address-space limit and a time bound, and the promise is checked: the reader
either accepts it or raises a ``UserError`` naming the file; the command exits 0 or 2 (1 for a check
that finds a fault), and an exit 2 is ONE line on stderr naming the file or argument, with no
traceback and no warning; within the bounds. The examples are derandomized (the same every run).
"""

from __future__ import annotations

import io
import json
import os
import re
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from gaitbot.app.cli import main
from gaitbot.bus.recording import read_log
from gaitbot.gait.eigen import EigenGaitModel
from gaitbot.gait.terrain.course_file import load_course
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.config import load_robot_config
from helpers import CONFIG_DIR, PY_WARNING, assert_cli_behaves, assert_reader_behaves, cli, isolated

EXAMPLES = int(os.environ.get("GAITBOT_FUZZ_EXAMPLES", "20"))
FUZZ = settings(max_examples=EXAMPLES, deadline=None, derandomize=True, database=None,
                phases=(Phase.explicit, Phase.generate), suppress_health_check=list(HealthCheck))
BIG = "1" + "0" * 400
HOSTILE_TOML = ["nan", "inf", "-inf", "-1", "0", "1e308", "-1e308", "1e-300", "1e-9", "1e9", BIG, "-" + BIG,
                '"x"', '""', "true", "[1]", "[]", "[1, 2]", "{ a = 1 }", "1979-05-27", "9223372036854775808",
                "[" * 3000 + "]" * 3000]
HOSTILE_JSON = [None, True, "", "fast", -1, 0, 10**30, 2**64, 10**400, 1e308, [], [1, 2], {}, {"a": 1}, "NaN",
                float("nan"), float("inf")]
HOSTILE_CELLS = ["nan", "inf", "", "abc", "1e308", "-1e308", "1+2j", "0x10", "9" * 131_073, "1" * 400, '"', "\x00"]


# --------------------------------------------------------------------------- mutations

@st.composite
def toml_mutation(draw, text: str) -> str:
    lines = text.splitlines()
    assignments = [i for i, line in enumerate(lines) if re.match(r"^\s*[A-Za-z_][\w.]*\s*=", line)]
    how = draw(st.sampled_from(["value", "value", "value", "delete", "duplicate", "truncate", "nest"]))
    if how == "value":
        i = draw(st.sampled_from(assignments))
        key = lines[i].split("=", 1)[0]
        lines[i] = f"{key}= {draw(st.sampled_from(HOSTILE_TOML))}"
    elif how == "delete":
        del lines[draw(st.sampled_from(assignments))]
    elif how == "duplicate":
        i = draw(st.sampled_from(assignments))
        lines.insert(i, lines[i])
    elif how == "truncate":
        return text[:draw(st.integers(0, len(text)))]
    else:
        lines.append("deep = " + "[" * 50_000 + "]" * 50_000)
    return "\n".join(lines) + "\n"


@st.composite
def csv_mutation(draw, text: str) -> str:
    lines = text.splitlines()
    how = draw(st.sampled_from(["cell", "cell", "cell", "truncate", "delete", "duplicate", "header"]))
    if how == "cell":
        row = draw(st.integers(1, len(lines) - 1))
        cells = lines[row].split(",")
        cells[draw(st.integers(0, len(cells) - 1))] = draw(st.sampled_from(HOSTILE_CELLS))
        lines[row] = ",".join(cells)
    elif how == "truncate":
        return text[:draw(st.integers(0, len(text)))]
    elif how == "delete":
        del lines[draw(st.integers(0, len(lines) - 1))]
    elif how == "duplicate":
        row = draw(st.integers(1, len(lines) - 1))
        lines.insert(row, lines[row])
    else:
        lines[0] = lines[0].replace(draw(st.sampled_from(lines[0].split(","))), "x", 1)
    return "\n".join(lines) + "\n"


def hostile_array(draw, like: np.ndarray) -> np.ndarray:
    kind = draw(st.sampled_from(["0d", "strings", "complex", "nan", "column", "transposed", "empty", "huge",
                                 "bool", "int"]))
    if like.dtype.kind not in "biuf":  # a text array (joint names, a model's kind): its numeric stand-in
        like = np.zeros(like.shape)
    if kind == "0d":
        return np.array(1.0)
    if kind == "strings":
        return np.array(["a", "b"])
    if kind == "complex":
        return like.astype(complex) + 1j
    if kind == "nan":
        bad = like.astype(float).copy()
        bad.reshape(-1)[draw(st.integers(0, max(0, bad.size - 1)))] = np.nan if bad.size else 0
        return bad
    if kind == "column":
        return like.reshape(-1, 1) if like.ndim else like.reshape(1, 1)
    if kind == "transposed":
        return like.T.copy() if like.ndim > 1 else like.reshape(-1)[::-1].copy()
    if kind == "empty":
        return np.zeros((0,) + like.shape[1:]) if like.ndim else np.zeros(0)
    if kind == "huge":
        return np.full(like.shape, 1e308)
    if kind == "bool":
        return like.astype(bool)
    return like.astype(np.int64)


def npz_bytes(arrays: dict) -> bytes:
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    return buffer.getvalue()


@st.composite
def npz_mutation(draw, arrays: dict) -> bytes:
    arrays = dict(arrays)
    how = draw(st.sampled_from(["array", "array", "array", "drop", "truncate", "claims"]))
    key = draw(st.sampled_from(sorted(arrays)))
    if how == "array":
        arrays[key] = hostile_array(draw, arrays[key])
    elif how == "drop":
        del arrays[key]
    elif how == "truncate":
        data = npz_bytes(arrays)
        return data[:draw(st.integers(0, len(data) - 1))]
    else:  # a header that claims a billion elements, with a few bytes behind it
        buffer = io.BytesIO()
        with zipfile.ZipFile(buffer, "w") as z:
            for name, value in arrays.items():
                if name == key:
                    header = {"descr": "<f8", "fortran_order": False, "shape": (10**9,)}
                    raw = io.BytesIO()
                    np.lib.format.write_array_header_1_0(raw, header)
                    z.writestr(name + ".npy", b"\x93NUMPY\x01\x00" + raw.getvalue()[8:] + b"\0" * 64)
                else:
                    raw = io.BytesIO()
                    np.save(raw, value)
                    z.writestr(name + ".npy", raw.getvalue())
        return buffer.getvalue()
    return npz_bytes(arrays)


@st.composite
def jsonl_mutation(draw, text: str) -> str:
    lines = text.splitlines()
    how = draw(st.sampled_from(["header", "header", "packet", "line", "truncate", "deep"]))
    if how == "header":
        header = json.loads(lines[0])
        header[draw(st.sampled_from(sorted(header) + ["rate_hz", "calibration"]))] = draw(st.sampled_from(HOSTILE_JSON))
        lines[0] = json.dumps(header)
    elif how == "packet":
        row = draw(st.integers(1, len(lines) - 1))
        packet = json.loads(lines[row])
        packet[draw(st.sampled_from(["t", "dir", "hex"]))] = draw(st.sampled_from(HOSTILE_JSON))
        lines[row] = json.dumps(packet)
    elif how == "line":
        lines[draw(st.integers(0, len(lines) - 1))] = draw(st.sampled_from(["", "{", "[]", "null", "\x00", "{}"]))
    elif how == "truncate":
        return text[:draw(st.integers(0, len(text)))]
    else:
        lines[draw(st.integers(0, len(lines) - 1))] = "[" * 100_000 + "]" * 100_000
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- valid files to mutate

@pytest.fixture(scope="module")
def base(tmp_path_factory) -> dict:
    d = tmp_path_factory.mktemp("hostile-base")
    steps = {s: ",".join([s] * 6) for s in ("0.03", "0.05", "0.07")}
    for argv in (["generate", "--distance", "0.3", "-o", d / "walk.csv"],
                 ["generate", "--distance", "0.3", "-o", d / "walk.npz"],
                 ["walk", "--dry-run", "--distance", "0.2", "--record", d / "rec.jsonl"],
                 *(["generate", "--steps", v, "-o", d / f"ex_{s}.npz"] for s, v in steps.items())):
        assert isolated(main, [str(a) for a in argv], capture=True)["value"] == 0, argv
    fit = ["eigen", "fit", *(d / f"ex_{s}.npz" for s in steps), "-o", d / "model.npz", "--n-basis", "11"]
    assert isolated(main, [str(a) for a in fit], capture=True)["value"] == 0
    with np.load(d / "walk.npz") as z:
        walk_npz = {k: z[k] for k in z.files}
    with np.load(d / "model.npz") as z:
        model_npz = {k: z[k] for k in z.files}
    return {"dir": d, "csv": (d / "walk.csv").read_text(), "rec": (d / "rec.jsonl").read_text(),
            "walk_npz": walk_npz, "model_npz": model_npz}


def write(tmp_path_factory, name: str, data: str | bytes) -> Path:
    path = tmp_path_factory.mktemp("case") / name
    path.write_bytes(data.encode("utf-8", "surrogateescape") if isinstance(data, str) else data)
    return path


ROBOTS = [(CONFIG_DIR / f"{name}.toml").read_text() for name in ("xl430-biped", "sts3215-biped", "ax12a-biped")]
COURSES = [p.read_text() for p in sorted((CONFIG_DIR / "terrain").glob("*.toml"))]
KERB = (CONFIG_DIR / "terrain" / "kerb.toml").read_text()


# --------------------------------------------------------------------------- readers in-process

@FUZZ
@given(text=st.sampled_from(ROBOTS).flatmap(toml_mutation))
def test_robot_config_reader(text, tmp_path_factory):
    path = write(tmp_path_factory, "robot.toml", text)
    assert_reader_behaves(isolated(load_robot_config, path), path)


@FUZZ
@given(text=st.sampled_from(COURSES).flatmap(toml_mutation))
def test_terrain_course_reader(text, tmp_path_factory):
    path = write(tmp_path_factory, "course.toml", text)
    assert_reader_behaves(isolated(load_course, path), path)


@FUZZ
@given(data=st.data())
def test_trajectory_csv_reader(data, base, tmp_path_factory):
    path = write(tmp_path_factory, "walk.csv", data.draw(csv_mutation(base["csv"])))
    assert_reader_behaves(isolated(Trajectory.load, path), path)


@FUZZ
@given(data=st.data())
def test_trajectory_npz_reader(data, base, tmp_path_factory):
    path = write(tmp_path_factory, "walk.npz", data.draw(npz_mutation(base["walk_npz"])))
    assert_reader_behaves(isolated(Trajectory.load, path), path)


@FUZZ
@given(data=st.data(), partial=st.booleans())
def test_recording_reader(data, partial, base, tmp_path_factory):
    path = write(tmp_path_factory, "rec.jsonl", data.draw(jsonl_mutation(base["rec"])))
    assert_reader_behaves(isolated(lambda p: read_log(p, allow_partial_last_line=partial) and None, path), path)


@FUZZ
@given(data=st.data())
def test_eigen_model_reader(data, base, tmp_path_factory):
    path = write(tmp_path_factory, "model.npz", data.draw(npz_mutation(base["model_npz"])))
    assert_reader_behaves(isolated(lambda p: EigenGaitModel.load(p) and None, path), path)


# --------------------------------------------------------------------------- the same files, and arguments, through the CLI

def assert_walk_behaves(result: dict) -> None:
    """A walk's input is accepted (0), refused as bad input (2), or refused before anything moved because the
    walk would break a limit: exit 1 since the docs work made a refused walk ``LimitBroken`` (as ``gaitbot
    check`` fails on the same file; docs/command-line.md), one line, nothing else and nothing on stdout."""
    assert_cli_behaves(result, allowed=(0, 1, 2))
    if result["value"] == 1:
        lines = [line for line in result["stderr"].splitlines() if line.strip()]
        assert len(lines) == 1 and lines[0].startswith("gaitbot walk: error: walk refused before anything moved: "), \
            result["stderr"]
        assert not result["stdout"].strip(), result["stdout"]


@FUZZ
@given(text=st.sampled_from(ROBOTS).flatmap(toml_mutation))
def test_walk_with_a_mutated_robot_config(text, tmp_path_factory):
    path = write(tmp_path_factory, "robot.toml", text)
    assert_walk_behaves(cli("walk", "--dry-run", "--distance", "0.1", "--robot", path))


@pytest.mark.slow
@FUZZ
@given(text=toml_mutation(KERB))  # the kerb: planning the stairs alone takes seconds on a loaded machine
def test_plan_with_a_mutated_course(text, tmp_path_factory):
    path = write(tmp_path_factory, "course.toml", text)
    assert_cli_behaves(cli("plan", "--terrain", path))


@FUZZ
@given(data=st.data(), kind=st.sampled_from(["csv", "npz", "rec"]))
def test_check_with_a_mutated_file(data, kind, base, tmp_path_factory):
    if kind == "csv":
        path = write(tmp_path_factory, "walk.csv", data.draw(csv_mutation(base["csv"])))
    elif kind == "npz":
        path = write(tmp_path_factory, "walk.npz", data.draw(npz_mutation(base["walk_npz"])))
    else:
        path = write(tmp_path_factory, "rec.jsonl", data.draw(jsonl_mutation(base["rec"])))
    assert_cli_behaves(cli("check", "--allow-partial", path), allowed=(0, 1, 2))


@pytest.mark.slow
@FUZZ
@given(data=st.data())
def test_eigen_synth_with_a_mutated_model(data, base, tmp_path_factory):
    path = write(tmp_path_factory, "model.npz", data.draw(npz_mutation(base["model_npz"])))
    out = path.parent / "synth.csv"
    assert_cli_behaves(cli("eigen", "synth", path, "--step-length", "0.05", "-o", out), allowed=(0, 1, 2))


HOSTILE_NUMBERS = ["nan", "inf", "-inf", "-1", "0", "1e-9", "1e9", "1e308", "-1e308", "abc", "", BIG, "0x10"]
WALK_OPTIONS = ["--rate", "--distance", "--max-step", "--perturb", "--clearance", "--thigh", "--shank", "--foot"]


@FUZZ
@given(option=st.sampled_from(WALK_OPTIONS), value=st.sampled_from(HOSTILE_NUMBERS),
       command=st.sampled_from(["plan", "generate", "walk"]))
def test_walk_options_with_hostile_numbers(option, value, command, tmp_path_factory):
    """A walk checks its plan against the robot's servos first: a valid but extreme leg (``--foot=1e-9``: no toe
    to roll over, so the knee flexes at lift-off faster than the XL430's 12000 deg/s^2) is refused before
    anything moves, exit 1 (the check found a fault, docs/command-line.md), in one line; plan and generate
    check no servo: 0 or 2."""
    extra = {"generate": ["-o", tmp_path_factory.mktemp("out") / "w.csv"], "walk": ["--dry-run"], "plan": []}[command]
    distance = [] if option == "--distance" else ["--distance", "0.1"]
    result = cli(command, *distance, f"{option}={value}", *extra)
    if command == "walk":
        assert_walk_behaves(result)
    else:
        assert_cli_behaves(result)


@pytest.mark.slow
@FUZZ
@given(option=st.sampled_from(["--cycles", "--components", "--step-length", "--to-step-length", "--pose-time"]),
       value=st.sampled_from(HOSTILE_NUMBERS + ["100000000", "-5", "3.5"]))
def test_eigen_synth_with_hostile_numbers(option, value, base, tmp_path_factory):
    out = tmp_path_factory.mktemp("out") / "w.csv"
    pose = ["--pose-deg", "0,0,0,0,0,0"] if option == "--pose-time" else []
    step = [] if option == "--step-length" else ["--step-length", "0.05"]
    assert_cli_behaves(cli("eigen", "synth", base["dir"] / "model.npz", *step, f"{option}={value}", *pose, "-o", out),
                       allowed=(0, 1, 2))


@FUZZ
@given(name=st.sampled_from(["", " ", ".", "/", "/dev/null", "/dev/zero", "/dev/full", "/nonexistent/x", "a\nb",
                             "x" * 5000, "config", "/proc/self/mem"]),
       use=st.sampled_from(["robot", "terrain", "trajectory", "check", "record", "output"]))
def test_hostile_file_names(name, use, tmp_path_factory):
    argv = {"robot": ["plan", "--distance", "0.1", "--robot", name],
            "terrain": ["plan", "--terrain", name],
            "trajectory": ["walk", "--dry-run", "--trajectory", name],
            "check": ["check", name],
            "record": ["walk", "--dry-run", "--distance", "0.1", "--record", name],
            "output": ["generate", "--distance", "0.1", "-o", name]}[use]
    assert_cli_behaves(cli(*argv), allowed=(2,))


FIT_OPTIONS = ["--samples", "--n-basis", "--roughness", "--pose-variance", "--pose-tolerance-deg", "--variance",
               "--components", "--label-degree"]


@pytest.mark.slow
@settings(FUZZ, max_examples=max(5, EXAMPLES // 2))
@given(option=st.sampled_from(FIT_OPTIONS), value=st.sampled_from(HOSTILE_NUMBERS + ["100000000", "2", "-5"]))
def test_eigen_fit_with_hostile_numbers(option, value, base, tmp_path_factory):
    out = tmp_path_factory.mktemp("out") / "m.npz"
    examples = [base["dir"] / f"ex_{s}.npz" for s in ("0.03", "0.05", "0.07")]
    assert_cli_behaves(cli("eigen", "fit", *examples, f"{option}={value}", "-o", out))


@pytest.mark.slow
@settings(FUZZ, max_examples=max(5, EXAMPLES // 2))
@given(data=st.data(), kind=st.sampled_from(["csv", "npz"]))
def test_eigen_fit_with_a_mutated_example(data, kind, base, tmp_path_factory):
    if kind == "csv":
        path = write(tmp_path_factory, "ex.csv", data.draw(csv_mutation(base["csv"])))
    else:
        path = write(tmp_path_factory, "ex.npz", data.draw(npz_mutation(base["walk_npz"])))
    examples = [base["dir"] / f"ex_{s}.npz" for s in ("0.03", "0.05", "0.07")]
    assert_cli_behaves(cli("eigen", "fit", *examples, path, "-o", path.parent / "m.npz"))


@pytest.mark.slow
@FUZZ
@given(option=st.sampled_from(["--duration", "--reply-timeout-ms"]), value=st.sampled_from(HOSTILE_NUMBERS))
def test_record_with_hostile_numbers(option, value, tmp_path_factory):
    out = tmp_path_factory.mktemp("out") / "r.csv"
    extra = [] if option == "--duration" else ["--duration", "0.1"]
    assert_cli_behaves(cli("record", "--dry-run", "--yes", f"{option}={value}", *extra, "-o", out))


EMULATOR_FLAGS = ["--late", "--error", "--silent", "--corrupt", "--fault-after-frames", "--fault-after-s",
                  "--close-after-frames", "--close-after-s", "--baudrate", "--return-delay-us", "--ids", "--hand-rate"]


@pytest.mark.slow
@FUZZ
@given(flag=st.sampled_from(EMULATOR_FLAGS),
       value=st.sampled_from(HOSTILE_NUMBERS + ["3:100", "9:100", "3:abc", "3:-5", "3:nan", "x:1", "3:overload",
                                                "3:melting", "1.5:3", "0.5:9", "1-300", "5-1"]))
def test_emulator_arguments(flag, value):
    """The emulator's command line: a chain configured, or one line (exit 2); never a traceback. Its options
    are parsed and checked here without serving (a valid chain would serve until stopped)."""
    from gaitbot.app.emulator import build_parser, config_from_args

    def configure(argv):
        args = build_parser().parse_args(argv)
        try:
            config_from_args(args)
        except (ValueError, KeyError, OSError) as exc:  # what the emulator's main prints as one line, exit 2
            assert "\n" not in str(exc).strip()
            return 2
        return 0

    robot = ["--robot", str(CONFIG_DIR / "xl430-biped.toml")] if flag not in ("--ids",) else ["--protocol", "dxl2"]
    result = isolated(configure, [*robot, f"{flag}={value}"], capture=True)
    assert result["outcome"] == "ok" and result["value"] in (0, 2), result
    assert "Traceback" not in result["stderr"] and not PY_WARNING.search(result["stderr"]), result["stderr"]
    lines = [line for line in result["stderr"].splitlines() if line.strip()]
    assert len(lines) <= 1, lines  # argparse's own refusals: one line too (the parser of gaitbot.app.cli)


def test_the_harness_can_fail():
    """The checks above fail on what they guard against: a traceback, two lines, a reader's stray exception."""
    with pytest.raises(AssertionError):
        assert_cli_behaves(isolated(lambda: 1 / 0, capture=True))
    with pytest.raises(AssertionError):
        assert_cli_behaves({"outcome": "ok", "value": 2, "stderr": "usage: x\ngaitbot: error: y\n", "stdout": ""})
    with pytest.raises(AssertionError):
        assert_reader_behaves(isolated(lambda: [][1]), Path("x.toml"))
    assert isolated(time.sleep, 60, bound_s=0.5)["outcome"] == "timeout"
    big = isolated(lambda: len(bytearray(8 * 2**30)))  # beyond the memory bound: the child fails, not the machine
    assert big["outcome"] == "raised" and big["type"] == "MemoryError"
