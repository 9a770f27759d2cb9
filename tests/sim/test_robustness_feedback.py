"""tools/robustness_feedback.py's route: a perturbed op3 written as an MJCF model, walked through the whole session
(``gaitbot walk --sim --sim-model --sim-map``) with the identity map.

Independent checks: the exported model's mass, as MuJoCo compiles it, is 1.2 x the total config/op3.toml states
(read from the file, not through gaitbot's config loader); its servos' kp is the XM430-W350's stall torque over
the row's error and its friction the row's; the walk's report comes back with the feedback asked for; and on the
unperturbed model the route walks as plain ``gaitbot walk --sim`` does (two code paths onto one physics).
"""

from __future__ import annotations

import math
import sys
import tomllib

import numpy as np
import pytest

from gaitbot.sim import SimUnavailable, import_mujoco  # noqa: E402  (picks the offscreen GL first)

try:
    mujoco = import_mujoco()
except SimUnavailable:
    pytest.skip("the sim extra (MuJoCo) is not installed", allow_module_level=True)

from helpers import CONFIG_DIR, REPO_ROOT  # noqa: E402

sys.path.insert(0, str(REPO_ROOT / "tools"))
import robustness_feedback as rf  # noqa: E402

XM430_STALL_NM = 4.1  # ROBOTIS e-Manual, XM430-W350 at 12 V (config/op3.toml's servos)
SHORT = ("--distance", "0.3")


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    return rf.Models(tmp_path_factory.mktemp("robustness-feedback"))


def test_the_mass_row_model_weighs_1_2_times_the_config_and_walks_through_the_session(models):
    row = next(r for r in rf.rows() if r.walk == "mass +20%" and r.robot.error_deg == rf.WRITTEN)
    model_path, map_path = models.model_and_map(row.robot)
    model = mujoco.MjModel.from_xml_path(str(model_path))
    stated_kg = tomllib.loads((CONFIG_DIR / "op3.toml").read_text())["mass"]["total_kg"]
    assert float(model.body_mass.sum()) == pytest.approx(1.2 * stated_kg, rel=1e-5)
    assert np.allclose(model.actuator_gainprm[:, 0], XM430_STALL_NM / math.radians(6.0), rtol=1e-6)
    assert np.allclose(model.geom_friction[:, 0], 1.0)
    frame_steps = (1 / 60) / model.opt.timestep
    assert frame_steps == pytest.approx(round(frame_steps), abs=1e-9)  # whole steps a frame, as the sim's own

    result = rf.play(models, rf.Row(row.group, row.walk, row.robot, SHORT), "full")
    assert set(result) >= {"fell", "travel", "drift_m", "roll_rms_deg", "pass"}
    assert not result["fell"] and 0.8 < result["travel"] < 1.2, result
    report = rf.walk(*SHORT, "--sim-model", str(model_path), "--sim-map", str(map_path), "--feedback", "none")
    assert report["feedback"] == "none" and report["distance_planned_m"] == pytest.approx(0.3)


def test_the_friction_row_changes_every_geom_and_only_the_friction(models):
    base = mujoco.MjModel.from_xml_string(rf.session_mjcf(models.config, 12.0))
    slippery = mujoco.MjModel.from_xml_string(rf.session_mjcf(models.config, 12.0, friction=0.6))
    assert np.all(slippery.geom_friction[:, 0] == 0.6) and np.all(base.geom_friction[:, 0] == 1.0)
    assert np.array_equal(slippery.geom_friction[:, 1:], base.geom_friction[:, 1:])
    assert np.array_equal(slippery.body_mass, base.body_mass)
    assert np.allclose(base.actuator_gainprm[:, 0], XM430_STALL_NM / math.radians(12.0), rtol=1e-6)


def test_the_identity_route_walks_as_plain_walk_sim(models):
    """The unperturbed model at the gain written, through --sim-model and the identity map, against plain
    ``gaitbot walk --sim``: the same physics, stepped the same, so the same walk within a few millimetres."""
    plain = rf.walk(*SHORT, "--feedback", "none")
    model_path, map_path = models.model_and_map(rf.OURS_WRITTEN)
    route = rf.walk(*SHORT, "--sim-model", str(model_path), "--sim-map", str(map_path), "--feedback", "none")
    assert not plain["fell"] and not route["fell"]
    assert route["distance_travelled_m"] == pytest.approx(plain["distance_travelled_m"], abs=0.005)
    assert route["lateral_drift_m"] == pytest.approx(plain["lateral_drift_m"], abs=0.005)
    assert route["torso_roll_rms_deg"] == pytest.approx(plain["torso_roll_rms_deg"], abs=0.1)
