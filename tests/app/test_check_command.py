"""gaitbot check on trajectory files through the real CLI, and tools/check_trajectory.py.

Trajectories come from ``gaitbot generate``; each edit breaks one limit of one joint at one time,
and the expected joint, time and limit are those of the edit (limits from the shipped TOML).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from helpers import REPO_ROOT, PERIOD_S, ROBOTS, run_cli

REPO = REPO_ROOT
COLUMNS = ["t_s", "hip_pitch_left_deg", "knee_pitch_left_deg", "ankle_pitch_left_deg", "hip_pitch_right_deg",
           "knee_pitch_right_deg", "ankle_pitch_right_deg", "root_x_m", "root_y_m", "root_z_m"]
VERSION_LINE = "# gaitbot trajectory 2"


@pytest.fixture(scope="module")
def walks(tmp_path_factory):
    from gaitbot.app.cli import main

    folder = tmp_path_factory.mktemp("walks")
    out = {}
    for robot in ROBOTS:
        path = folder / f"{robot}.csv"
        assert main(["generate", "--distance", "1", "--robot", robot, "-o", str(path)]) == 0
        out[robot] = path
    assert main(["generate", "--distance", "1", "-o", str(folder / "walk.npz")]) == 0
    out["npz"] = folder / "walk.npz"
    return out


def load(path):
    table = np.loadtxt(path, delimiter=",", skiprows=2)
    first, header = Path(path).read_text().splitlines()[:2]
    assert first.startswith(VERSION_LINE + " origin: ") and header == ",".join(COLUMNS)
    return table


def save(path, table):
    with open(path, "w") as f:
        f.write(VERSION_LINE + "\n" + ",".join(COLUMNS) + "\n")
        np.savetxt(f, table, delimiter=",", fmt="%.9g")
    return path


def row_at(table, t_s):
    return int(np.argmin(np.abs(table[:, 0] - t_s)))


@pytest.mark.parametrize("robot", ROBOTS)
def test_clean_trajectory_passes(capsys, walks, robot):
    code, out, err = run_cli(capsys, "check", walks[robot], "--robot", robot)
    assert code == 0, out + err
    assert "OK (0 errors, 0 warnings)" in out


def test_clean_npz_passes_with_json(capsys, walks):
    code, out, _ = run_cli(capsys, "check", walks["npz"], "--json")
    assert code == 0
    doc = json.loads(out)
    assert doc["ok"] and doc["kind"] == "trajectory" and doc["violations"] == []
    assert "forward differences" in doc["velocity_method"]


@pytest.mark.parametrize("robot", ROBOTS)
def test_knee_set_to_130_deg_at_2s(capsys, tmp_path, walks, robot):
    table = load(walks[robot])
    k = row_at(table, 2.0)
    table[k, 2] = 130.0  # knee_pitch_left; every shipped knee has max_deg 110
    path = save(tmp_path / "knee.csv", table)
    code, out, _ = run_cli(capsys, "check", path, "--robot", robot)
    assert code == 1
    assert f"knee_pitch_left: position 130.0 deg at t={table[k, 0]:.3f} s exceeds max_deg 110.0" in out
    assert abs(table[k, 0] - 2.0) <= PERIOD_S
    code, out, _ = run_cli(capsys, "check", path, "--robot", robot, "--json")
    doc = json.loads(out)
    pos = [v for v in doc["violations"] if v["kind"] == "position"]
    assert [(v["joint"], v["limit_name"], v["limit"], v["value"]) for v in pos] == [
        ("knee_pitch_left", "max_deg", 110.0, 130.0)]
    assert pos[0]["t_s"] == pytest.approx(table[k, 0])


def hip_limits(robot):
    """(max_velocity_dps, max_acceleration_dps2) of hip_pitch_left from the shipped TOML; the edits
    below are sized for 300 deg/s and 12000 deg/s^2."""
    from helpers import config

    joint = config(robot).joint("hip_pitch_left")
    assert (joint.max_velocity_dps, joint.max_acceleration_dps2) == (300.0, 12000.0)
    return joint.max_velocity_dps, joint.max_acceleration_dps2


def quiet_row(table, col, lo_s=1.0):
    """A row of the walk where the joint's own speed is smallest (a turning point), after lo_s."""
    v = np.abs(np.diff(table[:, col])) / np.diff(table[:, 0])
    k = int(np.argmin(np.where(table[1:, 0] > lo_s, v, np.inf))) + 1
    return k, float(v[k - 1])


def test_acceleration_kink_on_one_joint(capsys, tmp_path, walks):
    """One hip sample moved 2 deg: second difference 2*2/T^2 = 14400 deg/s^2 > 12000 at that sample only,
    neighbours 7200 deg/s^2 plus the walk's own (< 4000), speed change 120 deg/s (walk's hip < 130)."""
    robot = "xl430-biped"
    table = load(walks[robot])
    col = 1  # hip_pitch_left
    k, _ = quiet_row(table, col)
    dt = np.diff(table[:, 0])
    v = np.diff(table[:, col]) / dt
    own_acc = 2 * (v[k] - v[k - 1]) / (table[k + 1, 0] - table[k - 1, 0])
    table[k, col] += -2.0 if own_acc > 0 else 2.0  # against the walk's own acceleration there
    path = save(tmp_path / "kink.csv", table)
    code, out, _ = run_cli(capsys, "check", path, "--robot", robot, "--json")
    assert code == 1
    doc = json.loads(out)
    assert [(v["kind"], v["joint"], v["limit_name"], v["limit"]) for v in doc["violations"]] == [
        ("acceleration", "hip_pitch_left", "max_acceleration_dps2", hip_limits(robot)[1])]
    assert abs(doc["violations"][0]["t_s"] - table[k, 0]) <= PERIOD_S
    assert doc["violations"][0]["value"] >= 14400 - 1e-6


def test_speed_burst_on_one_joint(capsys, tmp_path, walks):
    """A smooth extra motion of the hip whose speed goes 110, 220, 330, 220, 110 deg/s on five intervals:
    6600 deg/s^2 steps (limit 12000 with the walk's own < 4000), one interval above 300 deg/s."""
    robot = "xl430-biped"
    table = load(walks[robot])
    col = 1
    k, own_speed = quiet_row(table, col)
    assert own_speed < 30
    extra_speed = np.array([110.0, 220.0, 330.0, 220.0, 110.0])
    start = k - 3  # intervals start..start+5: the third (330 deg/s) ends at row k
    offsets = np.concatenate([[0.0], np.cumsum(extra_speed * PERIOD_S)])
    table[start:start + 6, col] += offsets
    table[start + 6:, col] += offsets[-1]
    path = save(tmp_path / "burst.csv", table)
    code, out, _ = run_cli(capsys, "check", path, "--robot", robot)
    assert code == 1
    assert "velocity (1):" in out and "acceleration (" not in out and "position (" not in out
    line = next(x for x in out.splitlines() if "hip_pitch_left: velocity" in x)
    assert f"at t={table[k, 0]:.3f} s exceeds max_velocity_dps {hip_limits(robot)[0]:.1f}" in line


def test_margin_turns_near_misses_into_warnings(capsys, tmp_path, walks):
    table = load(walks["xl430-biped"])
    k = row_at(table, 3.0)
    table[k, 2] = 108.0  # 2 deg under the knee's max_deg 110; neighbours far below
    path = save(tmp_path / "near.csv", table)
    code, out, _ = run_cli(capsys, "check", path, "--margin-deg", "3", "--json")
    doc = json.loads(out)
    warns = [v for v in doc["violations"] if v["severity"] == "warning"]
    assert [(v["joint"], v["kind"], v["value"]) for v in warns] == [("knee_pitch_left", "position", 108.0)]


# ----------------------------------------------------------------------------------------- exit 2


def test_csv_missing_column(capsys, tmp_path, walks):
    lines = walks["xl430-biped"].read_text().splitlines()
    cut = [",".join(x.split(",")[:2] + x.split(",")[3:]) for x in lines]  # knee_pitch_left gone
    path = tmp_path / "nocol.csv"
    path.write_text("\n".join(cut) + "\n")
    code, out, err = run_cli(capsys, "check", path)
    assert code == 2 and out == ""
    assert "missing column 'knee_pitch_left_deg'" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("cut_from_end", [3, 40])
def test_truncated_csv(capsys, tmp_path, walks, cut_from_end):
    text = walks["xl430-biped"].read_text()
    path = tmp_path / "cut.csv"
    path.write_text(text[:-cut_from_end])
    code, _, err = run_cli(capsys, "check", path)
    assert code == 2 and "truncated" in err and len(err.strip().splitlines()) == 1


def test_truncated_npz(capsys, tmp_path, walks):
    data = walks["npz"].read_bytes()
    path = tmp_path / "cut.npz"
    path.write_bytes(data[: len(data) // 2])
    code, _, err = run_cli(capsys, "check", path)
    assert code == 2 and "cut.npz" in err and len(err.strip().splitlines()) == 1


def test_empty_and_missing_files(capsys, tmp_path):
    (tmp_path / "empty.csv").write_text("")
    (tmp_path / "empty.jsonl").write_text("")
    for name in ("empty.csv", "empty.jsonl", "absent.csv", "absent.jsonl"):
        code, out, err = run_cli(capsys, "check", tmp_path / name)
        assert code == 2 and out == "" and name in err and "Traceback" not in err


def test_negative_margin(capsys, walks):
    code, _, err = run_cli(capsys, "check", walks["xl430-biped"], "--margin-deg", "-1")
    assert code == 2 and "--margin-deg" in err


# ----------------------------------------------------------------------------------------- the tool and the real command


@pytest.mark.slow
def test_tool_script_same_exit_codes(tmp_path, walks):
    tool = REPO / "tools" / "check_trajectory.py"
    table = load(walks["xl430-biped"])
    ok = subprocess.run([sys.executable, str(tool), str(walks["xl430-biped"])], capture_output=True, text=True)
    assert ok.returncode == 0 and "OK" in ok.stdout
    table[row_at(table, 2.0), 2] = 130.0
    bad = subprocess.run([sys.executable, str(tool), str(save(tmp_path / "b.csv", table)), "--json"],
                         capture_output=True, text=True)
    assert bad.returncode == 1 and json.loads(bad.stdout)["ok"] is False
    gone = subprocess.run([sys.executable, str(tool), str(tmp_path / "none.csv")], capture_output=True, text=True)
    assert gone.returncode == 2 and gone.stdout == "" and len(gone.stderr.strip().splitlines()) == 1


def test_console_command_in_a_subprocess(tmp_path, walks):
    """python -m gaitbot.app.cli check, as a user runs it: one line on stderr, exit 2, no traceback."""
    path = tmp_path / "x.jsonl"
    path.write_text('{"t": 0.0, "dir": "tx", "hex": "ffff"}\n')
    run = subprocess.run([sys.executable, "-m", "gaitbot.app.cli", "check", str(path)], capture_output=True, text=True)
    assert run.returncode == 2 and "Traceback" not in run.stderr and "header" in run.stderr
    run = subprocess.run([sys.executable, "-m", "gaitbot.app.cli", "check", str(walks["ax12a-biped"]),
                          "--robot", "ax12a-biped"], capture_output=True, text=True)
    assert run.returncode == 0


def test_fast_csv_path_reads_what_trajectory_load_reads(walks):
    from gaitbot.gait.trajectory import load_fast as _load_trajectory
    from gaitbot.gait.trajectory import Trajectory

    fast, slow = _load_trajectory(walks["sts3215-biped"]), Trajectory.load(walks["sts3215-biped"])
    assert np.array_equal(fast.t_s, slow.t_s) and np.allclose(fast.angles_rad, slow.angles_rad, rtol=0, atol=1e-15)


def test_csv_with_a_non_number_is_exit_2(capsys, tmp_path, walks):
    lines = walks["xl430-biped"].read_text().splitlines()
    lines[10] = lines[10].replace(",", ",nan", 1)
    path = tmp_path / "nan.csv"
    path.write_text("\n".join(lines) + "\n")
    code, _, err = run_cli(capsys, "check", path)
    assert code == 2 and "nan.csv" in err and len(err.strip().splitlines()) == 1
