"""The one base of every "bad input" error in gaitbot: printed as one line, exit status 2.

A leaf: it imports nothing of gaitbot, so every room can subclass it (ConfigError, TerrainFileError,
TrajectoryFileError, StepLengthError, RecordingError, UsageError, ...) and the command line catches
``UserError`` alone. Each subclass keeps its built-in base too (``ValueError`` mostly), so code that
caught those still does.
"""

from __future__ import annotations


class UserError(Exception):
    """Input a person can fix (a file, a field, an argument); nothing was sent to a servo."""

    exit_status = 2
