"""Issue 26 item 4: motion is planned with a margin under the velocity and acceleration limits, and frames are
never bunched after a host stall, so a run judged at its send times stays within every limit."""

from __future__ import annotations

import numpy as np
import pytest

from gaitbot.check.trajectory import check_trajectory
from gaitbot.robot.calibration import angles_to_ticks, standing_ticks, ticks_to_angles
from gaitbot.robot.config import load_robot_config, resolve_config
from gaitbot.robot.motion_margin import MIN_SEND_INTERVAL_SHARE, PLANNED_SHARE
from gaitbot.robot.walk_settings import joint_limits_ticks
from gaitbot.stream import Streamer
from gaitbot.stream.clock import VirtualClock
from gaitbot.stream.ramps import ramp_ticks

PERIOD_S = 1 / 60


class TimedBus:
    """Records each goal frame with the time it went out; a write may hold the host up (a stall)."""

    def __init__(self, clock: VirtualClock, stalls_s: dict[int, float]) -> None:
        self.clock, self.stalls_s, self.sent = clock, stalls_s, []

    def write_goal_ticks(self, goals: dict[int, int]) -> None:
        self.sent.append((self.clock.now(), list(goals.values())))
        self.clock.advance(self.stalls_s.get(len(self.sent) - 1, 0.0005))


@pytest.mark.parametrize("robot", ["op3", "xl430-biped"])
@pytest.mark.parametrize("stall_s", [0.034, 0.050, 0.003])
def test_a_ramp_streamed_through_a_host_stall_keeps_every_limit_at_its_send_times(robot, stall_s):
    """The probe's case: a ramp at the planned speed, a write held up by the host, then the next frames. At
    their send times the joints stay within max_velocity_dps and max_acceleration_dps2 (planned at the
    limits and sent 0.9 period apart after a stall, they went 1.11 times over)."""
    config = load_robot_config(resolve_config(robot))
    velocity, acceleration = joint_limits_ticks(config)
    stand = standing_ticks(config)
    stand_deg = np.degrees(ticks_to_angles(config, stand[None, :])[0])
    lo, hi = (np.array([getattr(j, key) for j in config.joints]) for key in ("min_deg", "max_deg"))
    far_deg = np.where(hi - stand_deg > stand_deg - lo, hi - 1.0, lo + 1.0)  # each joint's longest way
    far = angles_to_ticks(config, np.radians(far_deg)[None, :])[0]
    frames = np.vstack([ramp_ticks(stand, far, velocity, acceleration, PERIOD_S),
                        ramp_ticks(far, stand, velocity, acceleration, PERIOD_S)])
    clock = VirtualClock(100.0)
    bus = TimedBus(clock, {k: stall_s for k in (20, 47, 90)})
    Streamer(bus, config.ids, PERIOD_S, clock).run(frames)
    t_s = np.array([t for t, _ in bus.sent])
    assert np.diff(t_s).min() >= MIN_SEND_INTERVAL_SHARE * PERIOD_S - 1e-12  # stretched, never bunched
    angles_deg = np.degrees(ticks_to_angles(config, np.array([g for _, g in bus.sent])))
    report = check_trajectory(config, t_s, angles_deg)
    assert report.ok, report.first_error
    worst = max(j.worst_velocity_dps / j.max_velocity_dps for j in report.joints)
    assert worst > PLANNED_SHARE * 0.95  # the ramp did cruise near its planned speed: the test is not idle


def test_the_planning_margin_is_what_ramps_are_planned_at():
    """One share, written once (gaitbot.robot.motion_margin), and what the ramps are planned at."""
    config = load_robot_config(resolve_config("op3"))
    slowest = min(j.max_velocity_dps for j in config.joints)
    ticks_per_deg = config.joints[0].model.ticks_per_rad * np.pi / 180
    assert joint_limits_ticks(config)[0] == pytest.approx(PLANNED_SHARE * slowest * ticks_per_deg)
    assert PLANNED_SHARE / MIN_SEND_INTERVAL_SHARE < 0.95  # room left for whole-tick rounding and stamp jitter
