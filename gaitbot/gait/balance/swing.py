"""The swing foot's path shape from the planar Boulic walker, tabulated per step length (docs/balance.md).

Why: the balanced walk keeps the Boulic model's character: the swing foot's progression towards its
foothold and its lift, as functions of swing time, are those the planar walker (gaitbot.gait.walker,
Jing et al. 2015) makes for that step length (its swing from toe-off to heel strike, relative to the stance
foot). The balanced walker scales them to its own footholds and clearance, with a flat sole (the ZMP
plan needs flat feet). A planar step takes tens of milliseconds to plan, so the shapes are tabulated
once per leg and cycle on a grid of step lengths and interpolated (appending a step stays cheap).

Ends: the planar swing leaves a rolling rear foot (with speed at toe-off) and lifts it steeply; a flat
foot must leave and land at rest, and a servo cannot follow a jump in acceleration. So over the first
and last END_BLEND of the swing the shape is replaced by a quintic that starts (ends) at rest with zero
acceleration and joins the Boulic shape with its value, slope and curvature: the motion is C2, and the
Boulic shape is kept exactly over the clearance window (20% to 80% of the swing).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from gaitbot.gait.contact import lowest_sole_y
from gaitbot.gait.geometry import LegGeometry
from gaitbot.gait.walk_segments import CLEARANCE_WINDOW, StepSegment
from gaitbot.gait.walker import WalkSettings, plan_walk

SHAPE_SAMPLES = 201
END_BLEND = 0.2  # share of the swing at each end given to the quintic join
TABLE_LENGTHS = 6  # step lengths tabulated, from 15% to 100% of the longest step


def _quintic(t, y0, y1, d1, c1, span):
    """Quintic on t in [0, 1] from y0 at rest (zero slope and curvature) to y1 with slope d1 and
    curvature c1 (per unit of the original variable, over ``span`` of it)."""
    d, c = d1 * span, c1 * span * span
    a3 = 10 * (y1 - y0) - 4 * d + c / 2
    a4 = -15 * (y1 - y0) + 7 * d - c
    a5 = 6 * (y1 - y0) - 3 * d + c / 2
    return y0 + a3 * t ** 3 + a4 * t ** 4 + a5 * t ** 5


def _rest_ends(y: np.ndarray, tau: np.ndarray, start: float, end: float) -> np.ndarray:
    """Replace y over [0, END_BLEND] and [1 - END_BLEND, 1] by quintic joins from ``start`` / to ``end``."""
    h = tau[1] - tau[0]
    dy = np.gradient(y, h)
    ddy = np.gradient(dy, h)
    out = y.copy()
    a = int(round(END_BLEND / h))
    b = len(y) - 1 - a
    out[:a + 1] = _quintic(tau[:a + 1] / END_BLEND, start, y[a], dy[a], ddy[a], END_BLEND)
    out[b:] = _quintic((1.0 - tau[b:]) / END_BLEND, end, y[b], -dy[b], ddy[b], END_BLEND)
    return out


@dataclass(frozen=True, eq=False)
class SwingShapes:
    """progression[i] (0 -> 1) and lift[i] (peak 1) over tau = linspace(0, 1) for step_lengths_m[i]."""

    step_lengths_m: np.ndarray
    tau: np.ndarray
    progression: np.ndarray  # (n_lengths, SHAPE_SAMPLES)
    lift: np.ndarray

    def at(self, travel_m: float) -> tuple[np.ndarray, np.ndarray]:
        """Shapes for a swing whose foot travels ``travel_m``: a steady planar step of half that length."""
        sl = np.clip(travel_m / 2.0, self.step_lengths_m[0], self.step_lengths_m[-1])
        i = int(np.clip(np.searchsorted(self.step_lengths_m, sl) - 1, 0, len(self.step_lengths_m) - 2))
        w = (sl - self.step_lengths_m[i]) / (self.step_lengths_m[i + 1] - self.step_lengths_m[i])
        return ((1 - w) * self.progression[i] + w * self.progression[i + 1],
                (1 - w) * self.lift[i] + w * self.lift[i + 1])

    def peak_for_clearance(self, lift_shape: np.ndarray, clearance_m: float) -> float:
        """Peak lift (m) that keeps the flat sole ``clearance_m`` up over the clearance window."""
        inside = (self.tau >= CLEARANCE_WINDOW[0]) & (self.tau <= CLEARANCE_WINDOW[1])
        return clearance_m / float(lift_shape[inside].min())


def planar_swing_shape(leg: LegGeometry, step_length_m: float, cycle_s: float, rate_hz: float,
                       clearance_m: float) -> tuple[np.ndarray, np.ndarray]:
    """(progression, lift) of the planar walker's steady swing at ``step_length_m``, resampled on tau."""
    walker = plan_walk(leg, [step_length_m] * 3, WalkSettings(cycle_s=cycle_s, rate_hz=rate_hz,
                                                              clearance=clearance_m))
    step = [s for s in walker.segments if isinstance(s, StepSegment)][1]  # from a step of sl to one of sl
    tau = np.linspace(0.0, 1.0, SHAPE_SAMPLES)
    u = step.u_toe_off + tau * (1.0 - step.u_toe_off)
    rel = step.swing_relative(u)
    ankle = step.root(u) + rel[:, :2]
    x = ankle[:, 0]
    progression = _rest_ends((x - x[0]) / (x[-1] - x[0]), tau, 0.0, 1.0)
    sole = lowest_sole_y(leg, ankle, rel[:, 2])
    sole = sole - np.linspace(sole[0], sole[-1], SHAPE_SAMPLES)  # both ends on the ground
    lift = np.maximum(_rest_ends(np.maximum(sole, 0.0), tau, 0.0, 0.0), 0.0)
    return progression, lift / lift.max()


@lru_cache(maxsize=16)
def swing_shapes(leg: LegGeometry, max_step_m: float, cycle_s: float, rate_hz: float,
                 clearance_m: float) -> SwingShapes:
    """Planar swing shapes for step lengths from 15% to 100% of ``max_step_m`` (cached per leg and cycle)."""
    lengths = np.linspace(0.15, 1.0, TABLE_LENGTHS) * max_step_m
    shapes = [planar_swing_shape(leg, float(sl), cycle_s, rate_hz, max(clearance_m, 1e-4)) for sl in lengths]
    return SwingShapes(lengths, np.linspace(0.0, 1.0, SHAPE_SAMPLES), np.array([s[0] for s in shapes]),
                       np.array([s[1] for s in shapes]))
