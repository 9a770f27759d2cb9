"""From eigen-gait coefficients to a walk: cycles in real time, joined to a start and a stop, and the
root from foot contact (Li et al. 2009 section 6; docs/gait-model.md section 3).

Choices (stated once):
- The model only knows steady cycles (left heel strike to left heel strike). A walk therefore
  starts and ends as the walker's do: the walker (Jing et al. 2015, Algorithm 2) takes the robot from
  standing through its first step to the first left heel strike; the synthesised cycles follow;
  the walker's closing step, settle and stand end it. Joint angles and velocities are made
  continuous at both joins by a quintic correction that fades over ``blend_cycles`` of a cycle
  (the correction is the difference between the walker's and the model's pose and velocity at
  the join, so it is small when the model is accurate). The default, a tenth of a cycle, keeps
  the correction inside the first and last 20% of the step next to each join, outside the part of
  the swing where the walker's clearance rule holds (walk_segments.CLEARANCE_WINDOW): fading over a
  quarter cycle instead took the last synthesised swing 7 mm lower, below the configured clearance.
- Transitions: the label (or the coefficients) is interpolated linearly from cycle to cycle, and
  within a cycle the coefficients go linearly from the cycle's start value to its end value, so
  the motion is continuous (Li et al. 2009 section 7, Figs. 8 and 9).
- Root: the contact model of the robot's walker, from the angles alone (legs.py): for the planar
  walker the stance foot rolls without slip about its lowest sole point and the root follows it in
  closed form (gait/footfall.py ``root_from_contact``, also used by ``gaitbot record``); for the
  balanced walker of a robot whose legs roll, the stance sole stays flat and still under an upright
  root, which gives the root's sideways sway and height too (gait/footfall3d.py).
- Start and stop come from the robot's own walker (``WalkEnds``): the planar walker's two-step walks,
  or the balanced walker's walks long enough that its preview control, which looks ahead to the stop,
  has not yet seen it at the first left heel strike.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..footfall import root_from_contact  # noqa: F401  (the planar contact rule; legs.py uses it)
from ..walk_segments import CLEARANCE_WINDOW
from ..geometry import LegGeometry
from ..trajectory import Trajectory
from .model import EigenGaitModel, EigenModelError


@dataclass(frozen=True)
class WalkEnds:
    """How a synthesised walk starts and stops: ``walk(step_m, n_steps)``, the robot's own walker's walk of
    ``n_steps`` steps of one length (a Trajectory of the model's joints, starting with the right foot), and
    ``steps``, how many steps those walks have. The walk's head runs to its first left heel strike, its tail
    from its last one."""

    walk: Callable[[float, int], Trajectory]
    steps: int = 2
    join_order: int = 1  # continuity at the joins: 1 angle and velocity, 2 also acceleration (join_smoothly)


def cycle_frames(model: EigenGaitModel, label_start: float, label_end: float, alpha_start, alpha_end, rate_hz: float):
    """One cycle at the frame rate: (angles (n, J), right-strike frame index)."""
    duration, warp, right_phase = model.timing_for(0.5 * (label_start + label_end))
    n = max(8, int(round(duration * rate_hz)))
    phase = np.arange(n) / n
    s = model.aligned_phase(phase, warp)
    alpha_start, alpha_end = np.asarray(alpha_start, float), np.asarray(alpha_end, float)
    angles = np.array([model.poses([si], alpha_start + si * (alpha_end - alpha_start))[0] for si in s]) \
        if np.any(alpha_start != alpha_end) else model.poses(s, alpha_start)
    return angles, int(round(right_phase * n))


def synthesize_cycles(model: EigenGaitModel, cycle_labels, rate_hz: float | None = None, components=None,
                      alphas=None):
    """Angles of consecutive cycles. ``cycle_labels``: labels at the n+1 cycle boundaries.

    ``alphas`` (n+1, m) overrides the coefficients at the boundaries (direct or pose synthesis).
    Returns (angles (N, J), list of cycle start frames (n+1 with the end), list of right-strike frames).
    """
    rate = model.rate_hz if rate_hz is None else rate_hz
    labels = list(cycle_labels)
    if alphas is None:
        alphas = [model.coefficients_for(label, components) for label in labels]
    chunks, starts, rights = [], [0], []
    for i in range(len(labels) - 1):
        angles, right = cycle_frames(model, labels[i], labels[i + 1], alphas[i], alphas[i + 1], rate)
        rights.append(starts[-1] + right)
        chunks.append(angles)
        starts.append(starts[-1] + len(angles))
    return np.vstack(chunks), starts, rights


def _quintic_fade(x, p0, v0):
    """Starts at p0 with slope v0 (per unit x), reaches 0 with zero slope and curvature at x = 1."""
    x = np.clip(np.asarray(x, float), 0.0, 1.0)[:, None]
    # basis: h0 (value 1, slope 0), h1 (value 0, slope 1), both with zero value/slope/curvature at 1
    h0 = 1 - 10 * x**3 + 15 * x**4 - 6 * x**5
    h1 = x - 6 * x**3 + 8 * x**4 - 3 * x**5
    return h0 * p0 + h1 * v0


def _quintic_fade2(x, p0, v0, a0):
    """Starts at p0 with slope v0 and curvature a0 (per unit x), reaches 0 with zero slope and curvature at x = 1."""
    x = np.clip(np.asarray(x, float), 0.0, 1.0)[:, None]
    h2 = 0.5 * x**2 - 1.5 * x**3 + 1.5 * x**4 - 0.5 * x**5  # value 0, slope 0, curvature 1 at 0; all 0 at 1
    return _quintic_fade(x[:, 0], p0, v0) + h2 * a0


def _continue(head: np.ndarray, body: np.ndarray, fade: int) -> np.ndarray:
    """The correction (len(body), J) that makes ``body`` continue ``head`` in angle, velocity and acceleration:
    at the body's first frame those of the parabola through the head's last three frames, one frame on."""
    d1, d2 = head[-1] - head[-2], head[-2] - head[-3]
    acc = d1 - d2
    want_p, want_v, want_a = head[-1] + d1 + acc, d1 + 1.5 * acc, acc
    got_v = (-3 * body[0] + 4 * body[1] - body[2]) / 2  # second-order one-sided differences
    got_a = body[0] - 2 * body[1] + body[2]
    x = np.arange(len(body)) / fade
    return _quintic_fade2(x, want_p - body[0], (want_v - got_v) * fade, (want_a - got_a) * fade**2)


def join_smoothly(head: np.ndarray, body: np.ndarray, tail: np.ndarray, fade_frames: int,
                  order: int = 1) -> np.ndarray:
    """head + body + tail, body corrected so angles and velocities (``order`` 1), and with ``order`` 2 also
    accelerations, are continuous at both joins.

    ``head`` ends with the frame just before the body's first; ``tail`` starts with the frame after
    the body's last. The correction fades over ``fade_frames`` at each end of the body. Order 2 is for a
    robot that balances: its root follows the stance leg's angles, and an acceleration that jumps at a join
    (order 1 makes it 0 for a frame) moves the ZMP by the CoM height times that jump over g, centimetres for
    the sway at a heel strike."""
    if order == 2:
        fade = max(3, min(fade_frames, len(body) // 2))
        body = body + _continue(head, body, fade)
        return np.vstack([head, body + _continue(tail[::-1], body[::-1], fade)[::-1], tail])
    body = body.copy()
    n = len(body)
    fade = max(2, min(fade_frames, n // 2))
    x = np.arange(n) / fade
    # at the start: the body's frame 0 should continue the head
    want0 = 2 * head[-1] - head[-2]
    got_v0 = body[1] - body[0]
    want_v0 = head[-1] - head[-2]
    body += _quintic_fade(x, want0 - body[0], (want_v0 - got_v0) * fade)
    # at the end: the body's last frame should lead into the tail
    xe = (n - 1 - np.arange(n)) / fade
    want_end = 2 * tail[0] - tail[1]
    got_ve = body[-1] - body[-2]
    want_ve = tail[1] - tail[0]
    body += _quintic_fade(xe, want_end - body[-1], -(want_ve - got_ve) * fade)
    return np.vstack([head, body, tail])


def check_labels(model: EigenGaitModel, labels, extrapolate: float = 0.0) -> None:
    lo, hi = model.label_range()
    span = hi - lo
    for label in labels:
        if not np.isfinite(label) or label < lo - extrapolate * span - 1e-12 or label > hi + extrapolate * span + 1e-12:
            raise EigenModelError(f"step length {label:g} m is outside the examples' range {lo:.4g} to {hi:.4g} m "
                                  f"(the label regression is only trusted between the examples)")


def assemble_walk(model: EigenGaitModel, head: Trajectory, body: np.ndarray, body_rights, body_cycle_starts,
                  tail: Trajectory, blend_frames: int, legs=None, join_order: int = 1) -> Trajectory:
    """Head (walker, ends just before a left heel strike) + body cycles + tail (walker, from a left heel strike);
    the root from contact of the legs (legs.py; default the model's), starting where the head starts."""
    legs = model.legs if legs is None else legs
    angles = join_smoothly(head.angles_rad, body, tail.angles_rad, blend_frames, join_order)
    rate = model.rate_hz
    t = np.arange(len(angles)) / rate
    root = legs.root_from_contact(angles, head.root_m[0])
    offset = len(head)
    events = [(int(round((h.t_s - head.t_s[0]) * rate)), h.leg) for h in head.heel_strikes
              if h.t_s < head.t_s[-1] + 0.5 / rate]
    events += [(offset + k, "left") for k in body_cycle_starts] + [(offset + k, "right") for k in body_rights]
    strikes = []
    tail_offset = offset + len(body)
    events += [(tail_offset + int(round((h.t_s - tail.t_s[0]) * rate)), h.leg) for h in tail.heel_strikes]
    for frame, leg in sorted(events):
        frame = min(frame, len(t) - 1)
        strikes.append(legs.heel_strike(angles, root, float(t[frame]), frame, leg))
    return Trajectory(t, angles, root, tuple(strikes), tuple(model.joints))


def _walker_part(geometry, settings, step_m: float, n_steps: int):
    from ..walker import plan_walk, trajectory_of

    return trajectory_of(plan_walk(geometry, [step_m] * n_steps, settings))


def _frame(trajectory: Trajectory, t_s: float) -> int:
    return int(np.argmin(np.abs(trajectory.t_s - t_s)))


def synthesize_walk(model: EigenGaitModel, settings, step_start_m: float, step_end_m: float | None = None,
                    cycles: int = 3, components: int | None = None, alphas=None,
                    blend_cycles: float = 0.5 * CLEARANCE_WINDOW[0], ends: WalkEnds | None = None,
                    legs=None) -> Trajectory:
    """A whole walk: the walker's start (its first steps at ``step_start_m``), ``cycles`` synthesised cycles
    (labels going linearly from ``step_start_m`` to ``step_end_m``), the walker's closing step and stand.

    ``alphas`` (cycles + 1, m): coefficients at the cycle boundaries instead of the label regression
    (the labels then only choose the timing and the walker's start and stop).
    ``settings``: the walker's WalkSettings; its rate must be the model's.
    ``ends``: the robot's walker for the start and stop (default: the planar walker of the model's leg);
    ``legs``: the contact rule of the root (legs.py; default the model's).
    """
    if cycles < 1:
        raise EigenModelError(f"--cycles must be 1 or more, got {cycles}")
    end = step_start_m if step_end_m is None else step_end_m
    check_labels(model, [step_start_m, end])
    if abs(settings.rate_hz - model.rate_hz) > 1e-6 * model.rate_hz:
        raise EigenModelError(f"the robot's frame rate {settings.rate_hz:g} Hz is not the model's {model.rate_hz:g} Hz")
    if ends is None:
        ends = WalkEnds(lambda step_m, n: _walker_part(model.geometry, settings, step_m, n))
    labels = list(np.linspace(step_start_m, end, cycles + 1))
    body, starts, rights = synthesize_cycles(model, labels, components=components, alphas=alphas)
    first = _ends_walk(model, ends, step_start_m)
    k_head = _frame(first, [h for h in first.heel_strikes if h.leg == "left"][0].t_s)
    head = Trajectory(first.t_s[:k_head], first.angles_rad[:k_head], first.root_m[:k_head],
                      tuple(h for h in first.heel_strikes if h.t_s < first.t_s[k_head] - 0.5 / model.rate_hz),
                      first.joints)
    last = first if end == step_start_m else _ends_walk(model, ends, end)
    lefts = [h for h in last.heel_strikes if h.leg == "left"]
    k_tail = _frame(last, lefts[-1].t_s)
    tail = Trajectory(last.t_s[k_tail + 1:], last.angles_rad[k_tail + 1:], last.root_m[k_tail + 1:],
                      tuple(h for h in last.heel_strikes if h.t_s > last.t_s[k_tail] + 0.5 / model.rate_hz),
                      last.joints)
    # the body's last cycle ends just before a left heel strike; the tail's first frame is just after
    # it, so the strike frame itself is the model's (its phase 1 = phase 0 of the next cycle)
    strike_pose = model.poses([0.0], alphas[-1] if alphas is not None else model.coefficients_for(end, components))
    body = np.vstack([body, strike_pose])
    starts = list(starts)
    fade = int(round(blend_cycles * len(body) / cycles))
    return assemble_walk(model, head, body, rights, starts, tail, fade, legs, ends.join_order)


def _ends_walk(model: EigenGaitModel, ends: WalkEnds, step_m: float) -> Trajectory:
    """The walker's walk for a start or a stop, which must move the model's joints."""
    walk = ends.walk(step_m, ends.steps)
    if tuple(walk.joints) != tuple(model.joints):
        raise EigenModelError(f"the robot's walker moves {', '.join(walk.joints)}, the model learnt "
                              f"{', '.join(model.joints)}: fit the model on this robot's walks")
    return walk
