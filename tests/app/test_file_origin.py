"""Files remember their robot: a trajectory names the robot (and its geometry's fingerprint) and the terrain
it was made for, a bus recording the calibration it was sent with; plot, check and walk --trajectory use
them by default and refuse a command line that contradicts them (one line, exit 2). Old files, without
these fields, are read as before."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from helpers import REPO_ROOT, knee_calibration, run_cli

DITCH = REPO_ROOT / "config" / "terrain" / "ditch.toml"  # one tread: a course walk planned in seconds
KERB = REPO_ROOT / "config" / "terrain" / "kerb.toml"
#: One worker runs this module, so that the files below (a course walk among them) are made once.
pytestmark = pytest.mark.xdist_group("file-origin")


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    from gaitbot.app.cli import main

    folder = tmp_path_factory.mktemp("origin")
    out = {"dir": folder}
    for name, argv in (("op3.csv", ["--robot", "op3", "--distance", "0.2"]),
                       ("op3.npz", ["--robot", "op3", "--distance", "0.2"]),
                       ("ditch.csv", ["--terrain", str(DITCH)])):
        assert main(["generate", *argv, "-o", str(folder / name)]) == 0
        out[name] = folder / name
    return out


def one_line_exit_2(result) -> str:
    code, out, err = result
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, (code, out, err)
    return err


def without_origin(path: Path, to: Path) -> Path:
    """The file as gaitbot wrote it before files remembered their robot."""
    from gaitbot.gait.trajectory import Trajectory

    replace(Trajectory.load(path), origin=None).save(to)
    return to


def test_the_file_names_its_robot_and_course(files):
    from gaitbot.gait.terrain.course_file import load_course
    from gaitbot.gait.trajectory import Trajectory, read_origin
    from gaitbot.robot.config import load_robot_config, resolve_config
    from gaitbot.robot.origin import geometry_fingerprint

    for name in ("op3.csv", "op3.npz"):
        origin = Trajectory.load(files[name]).origin
        assert origin == read_origin(files[name])
        assert origin.robot == "op3" and origin.treads == ()
        assert origin.robot_geometry == geometry_fingerprint(load_robot_config(resolve_config("op3")))
    ditch = Trajectory.load(files["ditch.csv"]).origin
    assert ditch.robot == "xl430-biped" and ditch.treads == load_course(DITCH).terrain.treads


def test_fingerprint_follows_the_geometry_only():
    from gaitbot.robot.config import load_robot_config, resolve_config
    from gaitbot.robot.origin import geometry_fingerprint

    op3 = load_robot_config(resolve_config("op3"))
    same = replace(op3, name="other", geometry=replace(op3.geometry, thigh_m=op3.geometry.thigh_m + 1e-9))
    longer = replace(op3, geometry=replace(op3.geometry, thigh_m=op3.geometry.thigh_m + 1e-3))
    assert geometry_fingerprint(same) == geometry_fingerprint(op3) != geometry_fingerprint(longer)


def test_plot_draws_the_files_robot(capsys, files, tmp_path):
    code, out, err = run_cli(capsys, "plot", files["op3.csv"], "-o", tmp_path / "x.png")
    assert code == 0 and "drawn for op3" in out, (out, err)
    old = without_origin(files["op3.csv"], tmp_path / "old.csv")
    code, out, _ = run_cli(capsys, "plot", old, "-o", tmp_path / "y.png")  # as before: the default robot
    assert code == 0 and "drawn for xl430-biped" in out


def test_plot_draws_the_files_course(capsys, files, tmp_path, monkeypatch):
    import gaitbot.plot
    from gaitbot.gait.terrain.course_file import load_course

    seen = {}
    monkeypatch.setattr(gaitbot.plot, "plot_trajectory",
                        lambda trajectory, geometry, path, **kw: seen.update(kw) or Path(path).write_bytes(b"png"))
    code, out, err = run_cli(capsys, "plot", files["ditch.csv"], "-o", tmp_path / "s.png")
    assert code == 0, err
    assert seen["terrain"].treads == load_course(DITCH).terrain.treads
    assert "on a course of 1 tread)" in out  # the ditch's one


def test_contradicting_robot_or_terrain_is_refused(capsys, files, tmp_path):
    err = one_line_exit_2(run_cli(capsys, "plot", files["op3.csv"], "--robot", "xl430-biped", "-o", tmp_path / "x.png"))
    assert "made for robot 'op3', not 'xl430-biped'" in err
    err = one_line_exit_2(run_cli(capsys, "check", files["op3.npz"], "--robot", "bioloid"))
    assert "made for robot 'op3'" in err
    err = one_line_exit_2(run_cli(capsys, "walk", "--dry-run", "--trajectory", files["op3.csv"], "--robot", "ax12a-biped"))
    assert "made for robot 'op3'" in err
    err = one_line_exit_2(run_cli(capsys, "plot", files["ditch.csv"], "--terrain", KERB, "-o", tmp_path / "y.png"))
    assert "walked on the course" in err and "ditch.toml" in err
    err = one_line_exit_2(run_cli(capsys, "plot", files["op3.csv"], "--terrain", KERB, "-o", tmp_path / "z.png"))
    assert "walked on flat ground" in err
    # saying what the file says is no contradiction
    code, _, err = run_cli(capsys, "plot", files["ditch.csv"], "--terrain", DITCH, "--robot", "xl430-biped",
                           "-o", tmp_path / "w.png")
    assert code == 0, err


def test_check_and_walk_use_the_files_robot(capsys, files):
    code, out, _ = run_cli(capsys, "check", files["op3.csv"])
    assert code == 0 and "checked against op3" in out
    code, out, err = run_cli(capsys, "walk", "--dry-run", "--trajectory", files["op3.npz"])
    assert code == 0 and out.startswith("op3: dry run"), (out, err)


def test_a_changed_geometry_is_refused(capsys, tmp_path):
    from gaitbot.app.cli import main

    config = tmp_path / "mine.toml"
    config.write_text((REPO_ROOT / "config" / "xl430-biped.toml").read_text().replace('name = "xl430-biped"',
                                                                                     'name = "mine"', 1))
    walk = tmp_path / "w.csv"
    assert main(["generate", "--robot", str(config), "--distance", "0.2", "-o", str(walk)]) == 0
    capsys.readouterr()
    code, out, _ = run_cli(capsys, "check", walk)  # found where it was
    assert code == 0 and str(config.resolve()) in json.dumps(walk.read_text().splitlines()[0])
    text = config.read_text()
    thigh = next(line for line in text.splitlines() if line.startswith("thigh_m = "))
    config.write_text(text.replace(thigh, f"thigh_m = {float(thigh.split('=')[1].split('#')[0]) + 0.001!r}", 1))
    err = one_line_exit_2(run_cli(capsys, "check", walk))
    assert "its [geometry] changed since" in err
    config.unlink()
    err = one_line_exit_2(run_cli(capsys, "plot", walk, "-o", tmp_path / "x.png"))
    assert "give it with --robot PATH" in err


@pytest.mark.parametrize("origin, field", [('{"robot": 3}', "robot"), ('{"colour": "red"}', "colour"),
                                           ('{"treads": [[0, -1, 0]]}', "length_m"), ("[1,", "JSON")])
def test_a_bad_origin_is_one_line(capsys, files, tmp_path, origin, field):
    lines = files["op3.csv"].read_text().splitlines(keepends=True)
    bad = tmp_path / "bad.csv"
    bad.write_text("# gaitbot trajectory 2 origin: " + origin + "\n" + "".join(lines[1:]))
    for argv in (["check", bad], ["plot", bad, "-o", tmp_path / "x.png"]):
        err = one_line_exit_2(run_cli(capsys, *argv))
        assert f"{bad}: line 1, origin" in err and field in err


def test_a_bad_npz_origin_is_one_line(capsys, files, tmp_path):
    arrays = dict(np.load(files["op3.npz"]))
    arrays["origin_treads"] = np.zeros((2, 2))
    bad = tmp_path / "bad.npz"
    np.savez(bad, **arrays)
    err = one_line_exit_2(run_cli(capsys, "check", bad))
    assert "origin_treads" in err




def test_a_recording_remembers_its_calibration(capsys, tmp_path):
    calibration = tmp_path / "knee.calibration.toml"
    calibration.write_text(knee_calibration(2600, -1))
    run = tmp_path / "run.jsonl"
    code, _, err = run_cli(capsys, "walk", "--dry-run", "--distance", "0.2", "--calibration", calibration,
                           "--record", run)
    assert code == 0, err
    lines = run.read_text().splitlines()
    header = json.loads(lines[0])
    assert header["calibration"]["joints"]["knee_pitch_left"] == {"zero_tick": 2600, "direction": -1}
    assert header["calibration"]["file"] == str(calibration.resolve())
    code, out, err = run_cli(capsys, "check", run)  # no --calibration again
    assert code == 0, out + err
    code, _, _ = run_cli(capsys, "check", run, "--calibration", calibration)  # the same one: fine
    assert code == 0
    other = tmp_path / "other.calibration.toml"
    other.write_text(knee_calibration(2610, -1))
    err = one_line_exit_2(run_cli(capsys, "check", run, "--calibration", other))
    assert "sent with another calibration" in err and "knee_pitch_left" in err
    # the same recording without the field (as written before headers kept it) fails as it did
    del header["calibration"]
    old = tmp_path / "old.jsonl"
    old.write_text("\n".join([json.dumps(header)] + lines[1:]) + "\n")
    code, out, _ = run_cli(capsys, "check", old)
    assert code == 1 and "knee_pitch_left" in out
    assert run_cli(capsys, "check", old, "--calibration", calibration)[0] == 0


@pytest.mark.parametrize("sent, field", [({"file": None}, "calibration must be"),
                                         ({"file": None, "joints": {"elbow": {"zero_tick": 1, "direction": 1}}},
                                          "elbow"),
                                         ({"file": None, "joints": {"knee_pitch_left": {"zero_tick": 1,
                                                                                        "direction": 0}}},
                                          "direction")])
def test_a_bad_calibration_header_is_one_line(capsys, tmp_path, sent, field):
    run = tmp_path / "run.jsonl"
    assert run_cli(capsys, "walk", "--dry-run", "--distance", "0.1", "--record", run)[0] == 0
    lines = run.read_text().splitlines()
    header = {**json.loads(lines[0]), "calibration": sent}
    run.write_text("\n".join([json.dumps(header)] + lines[1:]) + "\n")
    err = one_line_exit_2(run_cli(capsys, "check", run))
    assert "header calibration" in err and field in err


HOSTILE = [None, True, "", "x" * 300, -1, 10**400, 1e308, float("nan"), [], [[1, 2, 3, 4]], [[0, 1, float("inf")]],
           {}, {"a": 1}, [[True, 1, 0]], [[0, 1, 0]] * 101, "a\nb"]


@pytest.mark.parametrize("key", ["robot", "robot_config", "robot_geometry", "terrain", "treads"])
def test_hostile_origin_values_are_read_or_refused_in_one_line(files, tmp_path, key):
    """Every value of every field: the file loads (the value was acceptable) or TrajectoryFileError names it."""
    from gaitbot.gait.trajectory import Trajectory, TrajectoryFileError, read_origin

    rows = files["op3.csv"].read_text().split("\n", 1)[1]
    for value in HOSTILE:
        path = tmp_path / "h.csv"
        path.write_text("# gaitbot trajectory 2 origin: " + json.dumps({key: value}) + "\n" + rows)
        try:
            origin = Trajectory.load(path).origin
        except TrajectoryFileError as exc:
            assert str(path) in str(exc) and "\n" not in str(exc)
            continue
        assert origin == read_origin(path) and (value is None or getattr(origin, key) is not None)
