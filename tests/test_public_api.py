"""The curated public API of ``gaitbot``: its names are pinned, each resolves, and together they walk."""

from __future__ import annotations

import subprocess
import sys

import gaitbot

PUBLIC = ["__version__", "generate_walk", "Trajectory", "load_robot_config", "resolve_config", "angles_to_ticks",
          "make_robot_bus", "walk_session", "check_trajectory", "preflight", "UserError"]


def test_exported_names_are_pinned():
    assert gaitbot.__all__ == PUBLIC
    for name in PUBLIC:
        assert getattr(gaitbot, name) is not None, name


def test_import_gaitbot_is_light():
    """``import gaitbot`` loads no room: the API is imported when first used."""
    code = "import sys, gaitbot; print(sorted(m for m in sys.modules if m.startswith('gaitbot.')))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_the_api_walks_a_robot_on_the_mock_bus():
    from gaitbot.robot.walk_settings import joint_limits_ticks, leg_geometry, walk_settings
    from gaitbot.robot.calibration import standing_ticks
    from gaitbot.stream.clock import VirtualClock

    config = gaitbot.load_robot_config(gaitbot.resolve_config("xl430-biped"))
    walk = gaitbot.generate_walk(leg_geometry(config), [0.05, 0.08, 0.05], walk_settings(config))
    assert isinstance(walk, gaitbot.Trajectory)
    assert gaitbot.preflight(config, walk).ok
    velocity, acceleration = joint_limits_ticks(config)
    result = gaitbot.walk_session(gaitbot.make_robot_bus(config, dry_run=True), config.ids,
                                  gaitbot.angles_to_ticks(config, walk.angles_rad), standing_ticks(config),
                                  max_velocity_ticks_per_s=velocity, max_accel_ticks_per_s2=acceleration,
                                  period_s=1 / config.gait.rate_hz, clock=VirtualClock())
    assert result.outcome == "completed" and result.reached_stand
    assert issubclass(gaitbot.UserError, Exception)
