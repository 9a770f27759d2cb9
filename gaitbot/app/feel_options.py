"""``--feedback none|gyro|full`` of a walk: the IMU reader and the feedback of gaitbot.feel, or open loop."""

from __future__ import annotations

import sys

import numpy as np

from gaitbot.app.options import UsageError

FEEDBACK_CHOICES = ("none", "gyro", "full", "step", "zmp")


def add_feedback_option(p) -> None:
    p.add_argument("--feedback", choices=FEEDBACK_CHOICES, help="correct the goals from the robot's IMU: none (open "
                   "loop), gyro (gyro damping of ankles and hips), full (and the estimated tilt), step (full, and the "
                   "next foothold moved when a push needs a step; walk only), zmp (full, and the measured CoM error fed to the "
                   "walk's preview controller; walk only); default: full if the robot has an "
                   "[imu] (docs/feedback.md). A fall the IMU notices stops the walk (exit 1)")


def feedback_choice(args, config) -> str:
    """The mode asked for, or the robot's best; ``--feedback`` other than none on a robot without an IMU is
    refused (one line, exit 2). Says nothing else: call it with the other input checks, before any note."""
    asked = getattr(args, "feedback", None)
    if not config.imu.present:
        if asked not in (None, "none"):
            raise UsageError(f"--feedback {asked}: robot {config.name} has no IMU ([imu] source = \"none\")")
        return "none"
    return asked or "full"


def feedback_mode(args, config) -> str:
    """``feedback_choice``; a robot without an IMU walks open loop and says so once (call it once every
    check has passed: a refusal stays one line)."""
    mode = feedback_choice(args, config)
    if not config.imu.present:
        print(f"note: robot {config.name} has no IMU ([imu]): walking open loop", file=sys.stderr)
    return mode


def make_feedback(config, mode: str, bus, clock, period_s: float, sim=None):
    """The Feedback of a walk (None open loop without an IMU); its IMU faults are said once, on stderr.
    ``sim``: the simulated walk; on another author's model the feedback is told its servos' own stiffness
    (gains written to that model are not simulated: docs/simulation.md)."""
    if not config.imu.present:
        return None
    from gaitbot.feel.feedback import Feedback
    from gaitbot.feel.imu_reader import ImuReader

    def warn(text: str) -> None:
        print(f"\nwarning: {text}" if sys.stderr.isatty() else f"warning: {text}", file=sys.stderr, flush=True)

    reader = ImuReader(bus, config.imu, clock.now, period_s, on_fault=warn)
    servo_error_deg = foreign_servo_error_deg(sim)
    if servo_error_deg is not None and mode not in ("none", "gyro") and config.imu.attitude_roll_gain_by_servo_error:
        print(f"note: --sim-model: feedback for its servos (full torque at {servo_error_deg:.1f} deg of error): roll "
              f"attitude gain {config.imu.roll_gain(servo_error_deg):g}", file=sys.stderr)
    return Feedback(config, mode, reader, period_s, clock.now, servo_error_deg)


def foreign_servo_error_deg(sim) -> float | None:
    """The mean full-torque error (deg) of another author's model's mapped servos, or None on gaitbot's own."""
    robot = getattr(sim, "robot", None)
    if robot is None or not getattr(robot, "foreign", False):
        return None
    return float(np.mean(robot.full_torque_error_deg))


def fall_line(result, feedback) -> str | None:
    """The line that says when and which way the robot fell (the session's outcome "fell"), or None."""
    if result.outcome != "fell" or result.error is None:
        return None
    fell = result.error
    return f"The robot fell {fell.direction} at {fell.t_s:.2f} s ({fell.reason}); noticed by the IMU."


def fall_dict(result, true_tilt_crossed_s: float | None = None) -> dict | None:
    """The fall the IMU noticed, for --json; in the simulation also when the true tilt crossed the threshold."""
    if result.outcome != "fell" or result.error is None:
        return None
    fell = result.error
    return {"t_s": round(fell.t_s, 4), "direction": fell.direction, "reason": fell.reason,
            "true_tilt_crossed_s": None if true_tilt_crossed_s is None else round(true_tilt_crossed_s, 4)}
