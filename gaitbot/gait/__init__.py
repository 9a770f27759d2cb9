"""The gait room: pure numpy, no I/O but the trajectory file format and the terrain course reader.

Entry points: ``generate_walk`` (offline, whole trajectory), ``OnlineWalker`` (frame by frame),
``StepLengthInverse`` (step length <-> RV), ``steps_for_distance`` and ``perturb_steps``.
"""

from .geometry import TABLE1_LEG, LegGeometry
from .planning import PlannedStep, perturb_steps, steps_for_distance
from .walk_segments import GaitGenerationError
from .step_length import StepLengthError, StepLengthInverse
from .joints import LEG_JOINTS, PITCH_JOINTS
from .trajectory import HeelStrike, Trajectory, TrajectoryFileError
from .walker import OnlineWalker, WalkSettings, generate_walk, make_context

__all__ = [
    "TABLE1_LEG", "LegGeometry", "PlannedStep", "perturb_steps", "steps_for_distance", "GaitGenerationError",
    "StepLengthError", "StepLengthInverse", "LEG_JOINTS", "PITCH_JOINTS", "HeelStrike", "Trajectory", "TrajectoryFileError",
    "OnlineWalker", "WalkSettings", "generate_walk", "make_context",
]
