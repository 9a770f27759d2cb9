"""The exceptions that mean "bad input" everywhere in gaitbot: one line, exit status 2."""

from gaitbot.bus.log_decoder import RecordingError
from gaitbot.bus.sim import SimUnavailable, VideoError
from gaitbot.gait.eigen import EigenModelError, ExampleError
from gaitbot.gait.segments import GaitGenerationError
from gaitbot.gait.step_length import StepLengthError
from gaitbot.gait.trajectory import TrajectoryFileError
from gaitbot.robot.config import ConfigError
from gaitbot.session import UsageError
from gaitbot.terrain_file import TerrainFileError

USER_ERRORS = (UsageError, ConfigError, StepLengthError, TrajectoryFileError, RecordingError, GaitGenerationError,
               EigenModelError, ExampleError, TerrainFileError, SimUnavailable, VideoError)
