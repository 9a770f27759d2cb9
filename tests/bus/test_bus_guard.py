"""LimitGuard: no goal outside a joint's limits reaches a servo, whoever writes it."""

from __future__ import annotations

import numpy as np
import pytest

from gaitbot.bus.factory import make_dry_run_bus
from gaitbot.bus.guard import GoalOutsideLimits, LimitGuard
from gaitbot.stream.clock import VirtualClock
from gaitbot.robot.calibration import tick_limits
from gaitbot.robot.config import load_robot_config, resolve_config
from gaitbot.servos.models import servo_model
from gaitbot.stream import walk_session

XL430 = servo_model("XL430-W250")


def test_tick_limits_from_degrees():
    config = load_robot_config(resolve_config("xl430-biped"))
    limits = tick_limits(config)
    knee = config.joint("knee_pitch_left")  # -5..110 deg, zero 2048, direction +1, 4096 ticks per turn
    per_deg = 4096 / 360
    assert limits[knee.id] == (round(2048 - 5 * per_deg), round(2048 + 110 * per_deg))


def test_guard_refuses_before_sending():
    bus = make_dry_run_bus("dynamixel", 2.0, {1: XL430, 2: XL430})
    guarded = LimitGuard(bus, {1: (1000, 3000), 2: (1000, 3000)}, {1: "hip", 2: "knee"})
    with guarded:
        guarded.write_goal_ticks({1: 2000, 2: 2500})
        sent = len(bus.port.tx_packets)
        with pytest.raises(GoalOutsideLimits, match="3001 ticks for knee .servo 2., outside its limits 1000..3000"):
            guarded.write_goal_ticks({1: 2000, 2: 3001})
        assert len(bus.port.tx_packets) == sent, "nothing may be sent for a refused frame"


def test_session_with_a_servo_outside_its_limits_moves_nothing():
    # the mock chain starts at the centre tick 2048; limits 2100..2300 put every servo outside
    models = {i: XL430 for i in (1, 2, 3)}
    bus = make_dry_run_bus("dynamixel", 2.0, models)
    guarded = LimitGuard(bus, {i: (2100, 2300) for i in models})
    frames = np.full((10, 3), 2200)
    result = walk_session(guarded, [1, 2, 3], frames, np.full(3, 2200), max_velocity_ticks_per_s=3000,
                          max_accel_ticks_per_s2=30000, period_s=1 / 60, clock=VirtualClock(), handle_sigterm=False)
    assert result.exit_code == 1 and isinstance(result.error, GoalOutsideLimits)
    goal_writes = [p for p in bus.port.tx_packets if p[7] == 0x83]  # sync write instruction (protocol 2.0)
    assert goal_writes == []


def test_a_bus_layer_passes_on_every_ability_of_the_bus():
    """BusLayer (the LimitGuard's base) overrides every public method and attribute the Bus declares, so a
    layer never silently falls back to a Bus default instead of asking the bus under it."""
    import inspect

    from gaitbot.bus.base import Bus, BusLayer

    declared = {name for name, value in vars(Bus).items() if not name.startswith("_")}
    missing = sorted(name for name in declared if name not in vars(BusLayer))
    assert not missing, f"BusLayer does not pass on {missing}"
    assert {"write_goal_ticks", "read_back", "explain_status_error", "open_notes"} <= declared
    assert not any(inspect.isfunction(v) and k == "__getattr__" for k, v in vars(BusLayer).items())
