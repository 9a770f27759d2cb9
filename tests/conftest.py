"""Shared test plumbing: this folder on the path (for helpers.py), and the emulator module for tests.

Tests mirror the packages (tests/servos, gait, robot, bus, stream, check, sim, app); helpers.py holds
what several of them use. No test imports another test file, and the emulator is imported as the
module it is (gaitbot.bus.emulator), never loaded by file path.
"""
