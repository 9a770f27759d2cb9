"""Capture-point stepping in the simulated walk (``--feedback step``): a sideways push is answered (a moved
foothold, never against it, or a pause on both feet), and the recording of the pushed walk passes ``gaitbot
check`` (no feedback, no moved step, breaks a limit)."""

from __future__ import annotations

import json

import pytest

from gaitbot.sim import SimUnavailable, import_mujoco  # noqa: E402  (picks the offscreen GL first)

try:
    import_mujoco()
except SimUnavailable:
    pytest.skip("the sim extra (MuJoCo) is not installed", allow_module_level=True)

from helpers import run_cli  # noqa: E402

WALK = ("walk", "--sim", "--json", "--robot", "op3", "--distance", "1", "--cycle", "0.8", "--max-step", "0.06",
        "--imu-seed", "1")


@pytest.mark.parametrize("direction, axis, sign", [(90, 1, 1.0), (270, 1, -1.0)])
def test_a_sideways_push_is_answered_its_way_and_the_recording_checks(tmp_path, capsys, direction, axis, sign):
    record = tmp_path / "pushed.jsonl"
    code, out, err = run_cli(capsys, *WALK, "--feedback", "step", "--push", f"1.5@{direction}", "--record", record)
    assert code in (0, 1), err
    report = json.loads(out)
    moves, pauses = report["capture_steps"], report["capture_pauses_s"]
    assert moves or pauses, "the push was felt but nothing answered it"
    # the DCM error the IMU measured points the way the push went (left for 90 deg, right for 270): an
    # independent reading of the push's direction; no foothold ever moves against it (a push toward the foot
    # about to lift is waited out on both feet first: the next test)
    assert all(sign * m["dcm_error_m"][axis] > 0 for m in moves)
    assert all(sign * m["moved_m"][axis] >= 0 for m in moves)
    assert run_cli(capsys, "check", record)[0] == 0


def test_a_push_toward_the_foot_about_to_lift_pauses_the_walk_and_the_recording_checks(tmp_path, capsys):
    # pushed to the right in the left foot's swing: the right foot, queued to lift next, would leave the robot
    # on its left foot with the push carrying it further right; the walk waits on both feet instead
    record = tmp_path / "paused.jsonl"
    code, out, err = run_cli(capsys, *WALK, "--feedback", "step", "--push", "1.0@270", "--record", record)
    assert code in (0, 1), err
    report = json.loads(out)
    push = report["push"]
    assert push["leg"] == "left"
    pauses = report["capture_pauses_s"]
    assert pauses and push["start_s"] < pauses[0] < push["start_s"] + 0.25  # felt and answered at once
    assert len(pauses) <= 2  # stepping.MAX_PAUSES in a row
    assert run_cli(capsys, "check", record)[0] == 0


def test_without_a_push_nothing_moves_and_other_modes_report_no_steps(capsys):
    code, out, err = run_cli(capsys, *WALK, "--feedback", "step")
    assert code == 0, err
    report = json.loads(out)
    assert report["capture_steps"] == [] and report["capture_pauses_s"] == [] and not report["fell"]
    code, out, err = run_cli(capsys, *WALK, "--feedback", "full")
    assert "capture_steps" not in json.loads(out)


def test_the_zmp_correction_reports_itself_and_its_pushed_walks_recording_checks(tmp_path, capsys):
    record = tmp_path / "zmp.jsonl"
    code, out, err = run_cli(capsys, *WALK, "--feedback", "zmp", "--push", "1.0@90", "--record", record)
    assert code in (0, 1), err
    report = json.loads(out)
    assert report["feedback"] == "zmp" and "capture_steps" not in report
    felt = report["zmp_correction"]
    assert felt["frames"] > 100 and felt["max_offset_m"] > 0.001  # the push was felt and fed
    assert run_cli(capsys, "check", record)[0] == 0
