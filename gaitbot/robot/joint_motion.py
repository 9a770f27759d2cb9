"""The one definition of a joint's velocity and acceleration, as the servos see them.

A servo is sent whole ticks at frame times. So a motion's velocity and acceleration are measured on the
goal ticks (angles rounded to ticks as the stream rounds them, gaitbot.robot.calibration, and read back
in degrees) at the frame times:

* velocity: forward differences between consecutive frames, attributed to the later frame's time,
  over at most ``MAX_FRAME_PERIOD_S`` (a position servo makes a goal change within one frame of the
  slowest rate a walk streams at, whatever the time stamps say, so a slow rate cannot hide a jump);
* acceleration: second differences at the frames' own (possibly non-uniform) times,
  ``a_k = 2 (v_{k+1/2} - v_{k-1/2}) / (t_{k+1} - t_{k-1})``, attributed to the middle frame.

Everything that judges or plans motion uses this: ``gaitbot check`` on a trajectory file and on a
recording (at its send times), the preflight of ``gaitbot walk`` and ``gaitbot generate``, and the planners
that keep their walks at ``PLANNED_SHARE`` of the limits (gaitbot.robot.motion_margin): the balanced
walk's speed fit and the planar walk's cycle (gaitbot.robot.walk_settings).
"""

from __future__ import annotations

import numpy as np

from gaitbot.robot.calibration import angle_rad_to_ticks, joint_parameters, ticks_to_angle_rad

VELOCITY_METHOD = ("forward differences of the goal ticks between consecutive frames, attributed to the later "
                   "frame's time")
ACCELERATION_METHOD = ("second differences of the goal ticks with non-uniform spacing, "
                       "2*(v[k+1/2]-v[k-1/2])/(t[k+1]-t[k-1]), attributed to the middle frame's time")
#: The longest period a frame change is measured over (1 / 10 Hz, the lowest rate a walk streams at):
#: a goal 45 deg away is a 45 deg jump whether it comes 0.1 s or 1000 s after the one before.
MAX_FRAME_PERIOD_S = 0.1


def as_sent_deg(config, angles_deg) -> np.ndarray:
    """Angles (N, n_joints) in degrees, every joint of ``config``, as its servo is sent them: rounded to
    whole ticks as the stream rounds them, read back in degrees."""
    zero, direction, tpr = joint_parameters(config)
    ticks = angle_rad_to_ticks(np.radians(angles_deg), zero, direction, tpr)
    return np.degrees(ticks_to_angle_rad(ticks, zero, direction, tpr))


def joint_motion(t_s, sent_deg) -> tuple[np.ndarray, np.ndarray]:
    """(velocity (N-1, J) deg/s at t_s[1:], acceleration (N-2, J) deg/s^2 at t_s[1:-1]) of angles as
    sent (``as_sent_deg``) at frame times ``t_s`` (N,), strictly increasing."""
    t = np.asarray(t_s, dtype=float)
    q = np.asarray(sent_deg, dtype=float)
    dt = np.minimum(np.diff(t), MAX_FRAME_PERIOD_S)
    velocity = np.diff(q, axis=0) / dt[:, None]
    acceleration = 2.0 * np.diff(velocity, axis=0) / (dt[1:] + dt[:-1])[:, None]
    return velocity, acceleration


def limit_shares(config, t_s, angles_deg) -> tuple[np.ndarray, np.ndarray]:
    """Per joint of ``config`` (angles (N, n_joints) in degrees), the peak velocity and the peak
    acceleration as sent, each as a share of the joint's max_velocity_dps / max_acceleration_dps2."""
    velocity, acceleration = joint_motion(t_s, as_sent_deg(config, angles_deg))
    v_lim = np.array([j.max_velocity_dps for j in config.joints])
    a_lim = np.array([j.max_acceleration_dps2 for j in config.joints])
    v = np.abs(velocity).max(axis=0) if len(velocity) else np.zeros(len(v_lim))
    a = np.abs(acceleration).max(axis=0) if len(acceleration) else np.zeros(len(a_lim))
    return v / v_lim, a / a_lim


def peak_share(config, t_s, angles_deg) -> tuple[float, str]:
    """The largest share of a limit any joint's motion reaches (velocity or acceleration), and which:
    e.g. (0.87, "knee_pitch_left velocity 209 deg/s of 240")."""
    v, a = limit_shares(config, t_s, angles_deg)
    jv, ja = int(np.argmax(v)), int(np.argmax(a))
    if v[jv] >= a[ja]:
        joint = config.joints[jv]
        return float(v[jv]), (f"{joint.name} velocity {v[jv] * joint.max_velocity_dps:.0f} deg/s of "
                              f"{joint.max_velocity_dps:g}")
    joint = config.joints[ja]
    return float(a[ja]), (f"{joint.name} acceleration {a[ja] * joint.max_acceleration_dps2:.0f} deg/s^2 of "
                          f"{joint.max_acceleration_dps2:g}")
