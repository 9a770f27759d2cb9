"""tools/fast_walks.py's pieces: the changed Menagerie models, the configs with the speed fit's settings, the
steps-as-landed measure, and the premise of its settings table (each row one change from the shipped walk's).

Independent checks: the changed models are compiled by MuJoCo and compared with the unchanged one MuJoCo compiles
(not with the text the tool wrote); the configs are read with tomllib, not gaitbot's loader; the landed share of
a made-up walk is worked out by hand.
"""

from __future__ import annotations

import sys
import tomllib

import numpy as np
import pytest

from gaitbot.sim import SimUnavailable, import_mujoco

try:
    mujoco = import_mujoco()
except SimUnavailable:
    pytest.skip("the sim extra (MuJoCo) is not installed", allow_module_level=True)

from helpers import CONFIG_DIR, REPO_ROOT  # noqa: E402

sys.path.insert(0, str(REPO_ROOT / "tools"))
import fast_walks  # noqa: E402
import op3_menagerie  # noqa: E402


def _compiled(text: str):
    return mujoco.MjModel.from_xml_string(text)


def test_menagerie_variants_change_only_what_they_say():
    plain = _compiled(op3_menagerie.menagerie_mjcf())
    changed = _compiled(fast_walks.menagerie_variant(kp=1.5, force_nm=3.0, damping=2.0, friction=0.6))
    assert plain.nu == changed.nu > 0
    np.testing.assert_allclose(changed.actuator_gainprm[:, 0], 1.5 * plain.actuator_gainprm[:, 0])
    np.testing.assert_allclose(changed.actuator_biasprm[:, 1], 1.5 * plain.actuator_biasprm[:, 1])  # -kp
    np.testing.assert_allclose(changed.actuator_forcerange, np.tile([-3.0, 3.0], (changed.nu, 1)))
    np.testing.assert_allclose(plain.actuator_forcerange, np.tile([-5.0, 5.0], (plain.nu, 1)))
    hinges = plain.jnt_type[plain.dof_jntid] == mujoco.mjtJoint.mjJNT_HINGE
    np.testing.assert_allclose(changed.dof_damping[hinges], 2.0 * plain.dof_damping[hinges])
    assert plain.dof_damping[hinges].min() > 0
    np.testing.assert_allclose(changed.geom_friction[:, 0], 0.6)
    np.testing.assert_allclose(changed.body_mass, plain.body_mass)  # the robot itself is the same
    unchanged = _compiled(fast_walks.menagerie_variant())
    np.testing.assert_allclose(unchanged.actuator_gainprm, plain.actuator_gainprm)
    np.testing.assert_allclose(unchanged.dof_damping, plain.dof_damping)


def test_a_settings_config_differs_from_the_shipped_one_in_those_four_values_only():
    text = fast_walks.settings_config(70.0, 0.05, 1.0, 0.003)
    changed, shipped = tomllib.loads(text), tomllib.loads((CONFIG_DIR / "op3.toml").read_text())
    assert changed["balance"]["crouch_knee_deg"] == 70.0
    assert changed["balance"]["double_support_share"] == 0.05
    assert changed["balance"]["progression_end"] == 1.0
    assert changed["gait"]["clearance_m"] == 0.003
    for table, key in (("balance", "crouch_knee_deg"), ("balance", "double_support_share"),
                       ("balance", "progression_end"), ("gait", "clearance_m")):
        del changed[table][key], shipped[table][key]
    assert changed == shipped


def test_the_landed_share_is_the_heel_strikes_spacing_over_the_plans_without_the_closing_step():
    planned = [0.05, 0.10, 0.15, 0.20, 0.20]  # four 5 cm steps, then the closing step beside the other foot
    landed = [0.045, 0.085, 0.13, 0.17, 0.168]
    report = {"heel_strikes": [{"x_m": x, "planned_x_m": p} for x, p in zip(landed, planned)]}
    # the spacing of the first four strikes: 0.04 + 0.045 + 0.04 = 0.125 landed against 0.15 planned
    assert fast_walks.landed_share(report) == pytest.approx(0.125 / 0.15)


def test_each_settings_row_is_one_change_from_the_shipped_walks_and_the_last_is_both():
    from gaitbot.robot.config import load_robot_config

    config = load_robot_config(CONFIG_DIR / "op3.toml")
    rows = fast_walks.settings_rows(config)

    def values(row):
        _, b, g = row
        return {"crouch": b.crouch_knee_deg, "double support": b.double_support_share,
                "progression": b.progression_end, "clearance": g.clearance_m}

    shipped, *singles, both = (values(r) for r in rows)
    changed = [{k for k in shipped if single[k] != shipped[k]} for single in singles]
    assert changed == [{"progression"}, {"clearance"}]
    assert shipped["progression"] < both["progression"] and shipped["clearance"] > both["clearance"]
    assert both["double support"] < shipped["double support"] and both["crouch"] == shipped["crouch"]
    for single, keys in zip(singles, changed):
        assert all(single[k] == both[k] for k in keys)
