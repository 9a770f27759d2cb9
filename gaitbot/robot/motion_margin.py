"""The margin every planned motion keeps under the servos' velocity and acceleration limits.

A walk or a ramp is planned on a grid of equal periods, but goals go out at real send times: a frame held up
by the host is followed by one sent sooner, and a recording judged at its send times (``gaitbot check``)
shows the motion between them faster than planned. Planned exactly at ``max_velocity_dps``, a stop ramp
after a late frame measured 264 deg/s against op3's 240. So:

- every walk is planned within ``PLANNED_SHARE`` of each joint's ``max_velocity_dps`` and
  ``max_acceleration_dps2``, measured as the servos see them (gaitbot.robot.joint_motion): the balanced
  walk's speed fit (gaitbot.gait.balance.speed_fit via gaitbot.robot.balanced_walk), the planar and terrain
  walks' cycle (gaitbot.robot.planar_fit); start ramps and stop ramps
  (gaitbot.robot.walk_settings.joint_limits_ticks) likewise. The checks (``gaitbot check``, the preflight of
  ``walk`` and ``generate``) refuse what goes beyond the full limits (docs/checking.md);
- the stream never sends two goal frames closer than ``MIN_SEND_INTERVAL_SHARE`` of a period
  (gaitbot.stream.pacing): after a stall the motion is stretched, never bunched to catch up, and regains
  the lost time at (1 - MIN_SEND_INTERVAL_SHARE) of a period a frame.

Judged at send times, a planned motion then moves at most PLANNED_SHARE / MIN_SEND_INTERVAL_SHARE = 0.947 of
its limit (whole-tick rounding is inside the planned share: it is measured on the ticks sent); the rest
is for the send time stamps' own jitter. docs/bus-faults.md
says the same in words.
"""

from __future__ import annotations

PLANNED_SHARE = 0.9
"""Planned velocities and accelerations stay at or under this share of each joint's limits."""

MIN_SEND_INTERVAL_SHARE = 0.95
"""Two goal frames never go out closer than this share of the frame period (gaitbot.stream.pacing)."""

assert PLANNED_SHARE < MIN_SEND_INTERVAL_SHARE <= 1.0
