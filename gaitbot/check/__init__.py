"""The check room: checks only, reading files through the formats' own readers.

``trajectory`` (joint angles against a robot's limits: position, tick range, wrap seam, velocity,
acceleration), ``recording`` (a bus log: packets, ids, frame timing, and its goals through the same
trajectory check), ``settings`` (the gain writes a recording holds), ``preflight`` (what a walk runs
before anything moves).
"""

from gaitbot.check.preflight import preflight
from gaitbot.check.recording import RecordingReport, check_recording
from gaitbot.check.trajectory import CheckReport, Violation, check_trajectory, trajectory_angles_deg

__all__ = ["preflight", "check_recording", "RecordingReport", "check_trajectory", "trajectory_angles_deg",
           "CheckReport", "Violation"]
