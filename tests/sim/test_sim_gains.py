"""The simulated servo's stiffness is the gain register the session wrote into its control table.

A proportional servo loaded with half its stall torque deflects by half its full-torque error, and
that error is worked out here from the register value by the datasheet formulas (Dynamixel X:
885 x 128 / gain pulses, 4096 a turn; AX-12A: slope x 300/1023 deg), so the deflection says which
stiffness the simulated servo really had.
"""

from __future__ import annotations

import json
import math
import re

import pytest

from gaitbot.sim import SimUnavailable, import_mujoco  # noqa: E402  (picks the offscreen GL first)

try:
    import_mujoco()
except SimUnavailable:
    pytest.skip("the sim extra (MuJoCo) is not installed", allow_module_level=True)

from gaitbot.sim.physics import SimRobot  # noqa: E402
from gaitbot.sim.port import make_sim_bus  # noqa: E402
from gaitbot.app.cli import main  # noqa: E402
from gaitbot.stream.clock import VirtualClock  # noqa: E402
from gaitbot.robot.config import load_robot_config, resolve_config  # noqa: E402
from helpers import CONFIG_DIR, float_in_air  # noqa: E402

KNEE_LEFT = 1  # walking-joint index of knee_pitch_left


def x_error_deg(gain: int) -> float:
    return 885 * 128 / gain * 360 / 4096


def loaded_knee_deflection_deg(name: str, writes: list[tuple[int, int, int]]) -> tuple[float, float]:
    """(deflection, stall torque) of the left knee held at 0 under half its stall torque, in the air,
    after ``writes`` (address, length, value) went to its servo over the simulated bus."""
    config = load_robot_config(resolve_config(name))
    robot = SimRobot(config, 60.0)
    float_in_air(robot)
    clock = VirtualClock()
    bus = make_sim_bus(config, robot, clock.now)
    knee = config.walking_joints[KNEE_LEFT]
    with bus:
        for address, length, value in writes:
            bus.write_register([knee.id], address, length, value)
        bus.write_goal_ticks({knee.id: knee.zero_tick})
        bus.set_torque([knee.id], True)
        stall = knee.model.stall_torque_nm
        robot.data.qfrc_applied[robot.model.joint("knee_pitch_left").dofadr[0]] = 0.5 * stall
        clock.advance(2.0)
        bus.read_present_ticks([knee.id])  # a packet: the physics catches up with the clock
    return math.degrees(abs(robot.joint_angles_rad()[KNEE_LEFT])), stall


@pytest.mark.parametrize("gain", [640, 4978, 1200])
def test_an_x_series_servo_is_as_stiff_as_its_position_p_gain_register(gain):
    deflection, _ = loaded_knee_deflection_deg("xl430-biped", [(84, 2, gain)])
    assert deflection == pytest.approx(0.5 * x_error_deg(gain), rel=0.03)


def test_a_softer_gain_gives_a_larger_error_than_a_stiff_one():
    soft, _ = loaded_knee_deflection_deg("xl430-biped", [(84, 2, 400)])
    stiff, _ = loaded_knee_deflection_deg("xl430-biped", [(84, 2, 4000)])
    assert soft > 5 * stiff


def test_without_a_write_the_servo_has_its_factory_gain():
    deflection, _ = loaded_knee_deflection_deg("xl430-biped", [])
    assert deflection == pytest.approx(0.5 * x_error_deg(640), rel=0.03)  # XL430-W250 factory Position P Gain


def test_an_ax12a_takes_the_softer_of_its_two_compliance_slopes():
    deflection, _ = loaded_knee_deflection_deg("ax12a-biped", [(28, 1, 4), (29, 1, 16)])
    assert deflection == pytest.approx(0.5 * 16 * 300 / 1023, rel=0.03)


def test_an_sts3215_follows_its_p_coefficient():
    stiff, _ = loaded_knee_deflection_deg("sts3215-biped", [(55, 1, 1), (21, 1, 128)])
    factory, _ = loaded_knee_deflection_deg("sts3215-biped", [])
    assert factory / stiff == pytest.approx(128 / 32, rel=0.05)  # P proportional to 1 / error


def sim_json(capsys, *args: str) -> dict:
    capsys.readouterr()
    assert main(["walk", "--sim", "--boom", "--json", *args]) == 0
    return json.loads(capsys.readouterr().out)


def test_a_simulated_walk_walks_with_the_stiffness_the_config_had_written(capsys, tmp_path):
    text = (CONFIG_DIR / "xl430-biped.toml").read_text()
    factory = tmp_path / "factory.toml"
    factory.write_text(re.sub(r"(?m)^\[servo\]\nfull_torque_error_deg = .*\n", "", text))
    stiff = sim_json(capsys, "--robot", str(CONFIG_DIR / "xl430-biped.toml"), "--steps", "0.05,0.05")
    soft = sim_json(capsys, "--robot", str(factory), "--steps", "0.05,0.05")
    assert stiff["full_torque_error_deg"] == pytest.approx([x_error_deg(4978)] * 6)
    assert soft["full_torque_error_deg"] == pytest.approx([x_error_deg(640)] * 6)
    assert soft["max_tracking_error_deg"] > 2 * stiff["max_tracking_error_deg"]
