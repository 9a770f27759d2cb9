"""walk --sim --sim-model --sim-map: another author's model (MuJoCo Menagerie's OP3, meshes removed, written by
tools/op3_menagerie.py) with the shipped map config/sim-maps/op3-menagerie.toml; and the map's refusals.

Independent checks: the model's feet, placed in the walk's first pose through the map, sit where gaitbot's own
kinematics puts them (two descriptions of one robot by different authors: within a few mm); a map that flips
a sign or swaps two joints is refused in one line (exit 2) naming the field.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import numpy as np
import pytest

from gaitbot.sim import SimUnavailable, import_mujoco  # noqa: E402  (picks the offscreen GL first)

try:
    import_mujoco()
except SimUnavailable:
    pytest.skip("the sim extra (MuJoCo) is not installed", allow_module_level=True)

from gaitbot.app.cli import main  # noqa: E402
from helpers import CONFIG_DIR, REPO_ROOT, config, read_lines, run_cli  # noqa: E402

MAP = CONFIG_DIR / "sim-maps" / "op3-menagerie.toml"


@pytest.fixture(scope="module")
def menagerie_xml(tmp_path_factory) -> Path:
    sys.path.insert(0, str(REPO_ROOT / "tools"))
    import op3_menagerie

    path = tmp_path_factory.mktemp("menagerie") / "op3.xml"
    path.write_text(op3_menagerie.menagerie_mjcf())
    return path


def edited_map(tmp_path: Path, old: str, new: str) -> Path:
    """The shipped map with ``old`` replaced by ``new`` (several: separated by "|")."""
    text = MAP.read_text()
    for before, after in zip(old.split("|"), new.split("|")):
        assert before in text
        text = text.replace(before, after)
    path = tmp_path / "map.toml"
    path.write_text(text)
    return path


def test_the_mapped_feet_stand_where_gaitbots_kinematics_puts_them(menagerie_xml):
    from gaitbot.gait.kinematics6 import sole_centre
    from gaitbot.sim.foreign import ForeignRobot
    from gaitbot.sim.sim_map import load_sim_map

    cfg = config("op3")
    robot = ForeignRobot(cfg, 60.0, menagerie_xml, load_sim_map(MAP))
    q_deg = {"hip_pitch": 25.0, "knee_pitch": 50.0, "ankle_pitch": 25.0, "hip_roll": 5.0, "ankle_roll": -5.0}
    angles = {f"{k}_{s}": np.radians(v) for k, v in q_deg.items() for s in ("left", "right")}
    robot.place(angles, (0.0, 0.0, 0.3))
    data = robot.data
    torso = data.xpos[robot.torso_body]
    for side_index, side in enumerate(("left", "right")):
        q6 = np.radians([0.0, q_deg["hip_roll"], q_deg["hip_pitch"], q_deg["knee_pitch"], q_deg["ankle_pitch"],
                         q_deg["ankle_roll"]])
        ours = sole_centre(cfg.body.geometry, side, q6)
        foot = robot.foot_bodies[side_index]
        rot = data.xmat[foot].reshape(3, 3)
        # Menagerie's sole: its two boxes' union, centred 24 mm ahead of the ankle roll link's origin, 30.5 mm below
        sole = data.xpos[foot] + rot @ np.array([0.024, (1 if side == "left" else -1) * 0.0125, -0.0305])
        assert np.linalg.norm((sole - torso) - ours) < 0.005
    assert robot.lowest_sole_z_m() == pytest.approx(0.0, abs=1e-9)


def test_a_short_walk_on_the_menagerie_op3_completes_and_its_recording_passes_check(menagerie_xml, tmp_path, capsys):
    record = tmp_path / "walk.jsonl"
    code, out, err = run_cli(capsys, "walk", "--sim", "--json", "--robot", "op3", "--sim-model", menagerie_xml,
                             "--sim-map", MAP, "--distance", "0.3", "--record", record)
    assert code == 0, err
    report = json.loads(out)
    assert not report["fell"]
    assert report["distance_travelled_m"] == pytest.approx(report["distance_planned_m"], rel=0.15)
    # the model's own servos: kp 21.1 N m/rad, +-5 N m -> full torque at 13.6 deg (not the 6 deg gaitbot writes)
    assert report["full_torque_error_deg"][0] == pytest.approx(np.degrees(5 / 21.1), abs=0.01)
    assert "the model's own position servos" in err
    # the feedback is told those servos' stiffness, not the 6 deg the config writes: config/op3.toml's table gives
    # its soft end's roll attitude gain (0.4 from 10 deg)
    assert report["feedback_servo_error_deg"] == pytest.approx(np.degrees(5 / 21.1), abs=0.01)
    assert report["feedback_roll_attitude_gain"] == config("op3").imu.roll_gain(14.0) == 0.4
    assert "roll attitude gain 0.4" in err
    assert run_cli(capsys, "check", record)[0] == 0


@pytest.mark.parametrize("old, new, message", [
    ('knee_pitch_left = "l_knee"', 'knee_pitch_left = "-l_knee"',
     "joints.knee_pitch_left: = '-l_knee': the model's forward kinematics contradicts it"),
    ('hip_yaw_right = "r_hip_yaw"', 'hip_yaw_right = "-r_hip_yaw"', "flip its sign"),
    ('hip_pitch_left = "-l_hip_pitch"\n', 'hip_pitch_left = "-l_ank_pitch"\n',
     "joints.ankle_pitch_left: the model's joint 'l_ank_pitch' is already mapped to hip_pitch_left"),
    ('hip_roll_right = "r_hip_roll"\nhip_pitch_right = "r_hip_pitch"',
     'hip_roll_right = "r_hip_pitch"\nhip_pitch_right = "r_hip_roll"', "is it the right model joint?"),
    ('knee_pitch_left = "l_knee"', 'knee_pitch_left = "l_kne"', "the model has no hinge joint 'l_kne' (did you mean"),
    ('l_el = -45.0', '', "the model's actuated joint 'l_el' is neither mapped in [joints] nor held in [hold_deg]"),
    ('ankle_roll_right = "-r_ank_roll"', '', "joints: ankle_roll_right is not mapped"),
    ('head_pan = 0.0', 'head_pn = 0.0', "hold_deg.head_pn: the model has no joint 'head_pn'"),
    ('body = "body_link"', 'body = "torso"', "imu.body: the model has no body 'torso'"),
    ('[joints]|l_el = -45.0', '[joints]\nelbow_left = "l_el"|', "joints.elbow_left: not a joint of robot op3"),
])
def test_a_map_the_model_contradicts_is_refused_in_one_line(menagerie_xml, tmp_path, capsys, old, new, message):
    bad = edited_map(tmp_path, old, new)
    code, out, err = run_cli(capsys, "walk", "--sim", "--robot", "op3", "--sim-model", menagerie_xml,
                             "--sim-map", bad, "--distance", "0.3")
    assert code == 2
    err = err.strip()
    assert message in err and "\n" not in err, err
    assert f"error: {bad}: " in err


@pytest.mark.parametrize("args, message", [
    (["--sim-model", "m.xml"], "--sim-model and --sim-map go together"),
    (["--sim-map", str(MAP)], "--sim-model and --sim-map go together"),
    (["--sim-model", "missing.xml", "--sim-map", str(MAP)], "--sim-model missing.xml: no such file"),
    (["--sim-model", "m.xml", "--sim-map", str(MAP), "--boom"], "--sim-model: another author's model stands free"),
    (["--push", "1@x"], "--push must be IMPULSE[@DIRECTION]"),
])
def test_what_a_foreign_model_cannot_do_is_one_line_and_exit_2(args, message, capsys):
    assert main(["walk", "--sim", "--robot", "op3", *args]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err, err


def test_a_model_that_is_not_mjcf_is_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.xml"
    bad.write_text("<mujoco><worldbody><body>")
    assert main(["walk", "--sim", "--robot", "op3", "--sim-model", str(bad), "--sim-map", str(MAP)]) == 2
    err = capsys.readouterr().err.strip()
    assert f"--sim-model {bad}: MuJoCo cannot load it" in err and "\n" not in err


def test_strong_feedback_with_a_push_on_the_menagerie_op3_breaks_no_limit(menagerie_xml, tmp_path, capsys):
    """Feedback never breaks a limit, pushes included: gains far above the op3's (every damping 0.3 s, the
    attitude 2 deg per deg in both axes, corrections up to 20 deg) on another author's model, pushed forwards
    with 1.5 N s; whether it falls or not, `gaitbot check` passes the recording (up to the fall and its stop),
    and the goals sent are not the open-loop walk's (the feedback acted)."""
    text = (CONFIG_DIR / "op3.toml").read_text()
    for key, value in (("ankle_pitch_s", "0.3"), ("hip_pitch_s", "0.3"), ("ankle_roll_s", "0.3"), ("hip_roll_s", "0.3"),
                       ("attitude_roll_gain_by_servo_error", "[[6.0, 2.0]]"), ("attitude_pitch_gain", "2.0"),
                       ("max_correction_deg", "20.0")):
        text, count = re.subn(rf"^{key} = .*$", f"{key} = {value}", text, flags=re.M)
        assert count == 1, key
    strong = tmp_path / "op3-strong.toml"
    strong.write_text(text)
    goals = {}
    for mode in ("none", "full"):
        record = tmp_path / f"{mode}.jsonl"
        code, out, err = run_cli(capsys, "walk", "--sim", "--json", "--robot", strong, "--sim-model", menagerie_xml,
                                 "--sim-map", MAP, "--distance", "0.6", "--max-step", "0.05", "--cycle", "1.0",
                                 "--push", "1.5@0", "--feedback", mode, "--record", record)
        assert code in (0, 1), err
        assert json.loads(out)["feedback"] == mode
        assert run_cli(capsys, "check", "--robot", strong, record)[0] == 0
        goals[mode] = [row["hex"] for row in read_lines(record)[1:] if row["dir"] == "tx"][:400]
    assert goals["none"] != goals["full"]


@pytest.mark.parametrize("timestep_s, steps", [(0.002, 9), (0.000980392, 17), (1 / 1020, 17), (0.001, 17),
                                               (0.0166667, 1), (0.02, 1)])
def test_a_frame_holds_whole_physics_steps_a_rounded_timestep_included(timestep_s, steps):
    """At 60 Hz: 2 ms -> 9 steps (1.85 ms each), 1 ms -> 17 (0.98 ms), and 1/1020 s written to six digits
    (0.000980392, as MJCF files carry it) is 17 steps, not 18; a timestep longer than the frame is one step."""
    from gaitbot.sim.foreign import substeps_per_frame

    assert substeps_per_frame(1 / 60, timestep_s) == steps


def test_the_models_own_bodies_touching_each_other_are_reported(menagerie_xml, tmp_path, capsys):
    """Another author's model may collide links that gaitbot's own models never do (Menagerie's OP3 has a
    collision mesh on every link). The stripped model collides its soles only, which the plan keeps 10 mm or
    more apart: nothing of it touches itself. Give each shank a capsule 36 mm in radius about its leg's line
    (35 mm from the middle: the two overlap by 2 mm) and the report names that pair, from the walk's start."""
    import re

    plain = run_cli(capsys, "walk", "--sim", "--json", "--robot", "op3", "--sim-model", menagerie_xml,
                    "--sim-map", MAP, "--distance", "0.1")
    assert plain[0] == 0 and json.loads(plain[1])["self_contacts"] == []
    fat = tmp_path / "fat-shanks.xml"
    fat.write_text(re.sub(r'(<joint name="([lr])_knee" axis="[^"]*"/>)',
                          lambda m: m.group(1) + '<geom type="capsule" fromto="0 {0} -0.03 0 {0} -0.08" size="0.036" '
                          'mass="0"/>'.format(-0.019 if m.group(2) == "l" else 0.019),
                          menagerie_xml.read_text()))
    code, out, err = run_cli(capsys, "walk", "--sim", "--json", "--robot", "op3", "--sim-model", fat, "--sim-map", MAP,
                             "--distance", "0.1")
    report = json.loads(out)
    touched = report["self_contacts"]
    assert [c["bodies"] for c in touched] == [["l_knee_link", "r_knee_link"]], touched
    assert touched[0]["first_s"] < report["heel_strikes"][0]["t_s"] and touched[0]["frames"] > 10  # before a step
    code, out, err = run_cli(capsys, "walk", "--sim", "--robot", "op3", "--sim-model", fat, "--sim-map", MAP,
                             "--distance", "0.1")
    assert "The robot's own bodies touched: l_knee_link and r_knee_link (" in out
