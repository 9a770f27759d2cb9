"""gaitbot: walking gaits for small servo bipeds.

Rooms, data flowing one way (docs/architecture.md; a checked contract):
servos (vendor facts) -> gait (angles over time) -> robot (config, calibration) -> bus (packets)
-> stream (the 60 Hz clock) and check (limits); sim and plot above them; app (the command line) on top.

The public API, a few names for scripts (imported when first used, so ``import gaitbot`` stays light)::

    import gaitbot
    config = gaitbot.load_robot_config(gaitbot.resolve_config("xl430-biped"))
    walk = gaitbot.generate_walk(geometry, [0.05, 0.08, 0.08], settings)      # a Trajectory
    report = gaitbot.preflight(config, walk)                                  # its limits checked
    bus = gaitbot.make_robot_bus(config, dry_run=True)                        # behind its LimitGuard
    result = gaitbot.walk_session(bus, config.ids, gaitbot.angles_to_ticks(config, walk.angles_rad), ...)
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

#: Public name -> the module that defines it.
_API = {
    "generate_walk": "gaitbot.gait.walker",
    "Trajectory": "gaitbot.gait.trajectory",
    "load_robot_config": "gaitbot.robot.config",
    "resolve_config": "gaitbot.robot.config",
    "angles_to_ticks": "gaitbot.robot.calibration",
    "make_robot_bus": "gaitbot.bus.factory",
    "walk_session": "gaitbot.stream.session",
    "check_trajectory": "gaitbot.check.trajectory",
    "preflight": "gaitbot.check.preflight",
    "UserError": "gaitbot.errors",
}

__all__ = ["__version__", *_API]


def __getattr__(name: str):
    if name in _API:
        value = getattr(importlib.import_module(_API[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'gaitbot' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
