"""The simulated robot: a MuJoCo model of the robot config behind the same packets as a real bus.

    make_sim_bus(config, robot, now, recorder=None) -> Bus     gaitbot.sim.port

model.py builds the MJCF from the robot config, physics.py steps it on the streamer's clock (a
callable: this room does not import the stream room), port.py is the serial port the real
Dynamixel/Feetech packet code talks to, metrics.py says whether the walk really walked, video.py
renders it, walk.py joins them to the walker's plan; docs/simulation.md explains the model. MuJoCo
is an optional dependency (the ``sim`` extra); :func:`import_mujoco` turns its absence into one line
that says how to install it.
"""

from __future__ import annotations

import os

from gaitbot.errors import UserError

SIM_EXTRA_HINT = "install the sim extra: pip install 'gaitbot[sim]'"


class SimUnavailable(UserError, ImportError):
    """An optional dependency of the simulation is missing; the message says how to install it."""


class VideoError(UserError, ValueError):
    """A video cannot be made (a file name we cannot write, or no offscreen rendering): one line."""


def import_mujoco():
    """The ``mujoco`` module, or SimUnavailable naming the extra to install.

    Offscreen rendering needs a GL backend chosen before mujoco is imported: EGL unless the
    user chose one (MUJOCO_GL=osmesa for pure software rendering)."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    try:
        import mujoco
    except ImportError:
        raise SimUnavailable(f"the simulated robot needs MuJoCo, which is not installed: {SIM_EXTRA_HINT}") from None
    return mujoco
