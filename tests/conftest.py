"""Shared test plumbing: this folder on the path (for helpers.py), and the emulator module for tests.

Tests mirror the packages (tests/servos, gait, robot, bus, stream, check, sim, app); helpers.py holds
what several of them use. No test imports another test file, and the emulator is imported as the
module it is (gaitbot.emulator), never loaded by file path.
"""

import pytest

#: Modules whose tests run against a servo emulator or a real-time clock: they go to one worker, one at a
#: time (pytest-xdist's loadgroup), since two real-time walks on a 2-core host delay replies past the SDK's
#: timeouts, which the driver rightly reports as servos answering late.
REAL_TIME_MODULES = {"test_emulator_e2e.py", "test_record_emulator.py", "test_walk_signals.py",
                     "test_session_gains.py"}


def pytest_collection_modifyitems(items):
    for item in items:
        if item.path.name in REAL_TIME_MODULES:
            item.add_marker(pytest.mark.xdist_group("real-time"))
