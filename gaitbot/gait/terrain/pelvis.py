"""The pelvis path of Zhang 2008: cubic Bezier segments between knots in time.

Knots are the mid-stance points (MS: the pelvis over the stance ankle, highest), the
mid-double-support points (MDS: lowest, chosen by the grid search), and the ends of a run of
terrain steps (where the flat walker hands over or takes back). Each knot has a time, a
position and a velocity; the segment between knots i and i+1 is the cubic Bezier with control
points P_i, P_i + V_i dt/3, P_(i+1) - V_(i+1) dt/3, P_(i+1) over its time span dt, so position and
velocity are continuous at every knot (the curve is C1), as joint velocities must be.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import comb

import numpy as np


def bernstein(n: int, s) -> np.ndarray:
    """Bernstein polynomials of degree n at s (m,): (m, n + 1)."""
    s = np.atleast_1d(np.asarray(s, dtype=float))[:, None]
    k = np.arange(n + 1)[None, :]
    return np.array([comb(n, i) for i in range(n + 1)])[None, :] * s**k * (1 - s) ** (n - k)


def bezier(control, s) -> np.ndarray:
    """Points of the Bezier curve with control points (n + 1, d) at parameters s: (m, d) (Zhang 2008 eq. 1-3)."""
    control = np.asarray(control, dtype=float)
    return bernstein(len(control) - 1, s) @ control


@dataclass(frozen=True)
class Knot:
    t: float  # seconds
    pos: tuple[float, float]  # metres
    vel: tuple[float, float]  # metres per second
    kind: str  # "start", "MDS", "MS", "end"


class PelvisPath:
    """Piecewise cubic Bezier through knots (sorted by time); evaluated on arrays of time."""

    def __init__(self, knots) -> None:
        self.knots = tuple(knots)
        t = np.array([k.t for k in self.knots])
        if len(t) < 2 or np.any(np.diff(t) <= 0):
            raise ValueError("pelvis knots need at least two strictly increasing times")
        self.t = t
        p = np.array([k.pos for k in self.knots], dtype=float)
        v = np.array([k.vel for k in self.knots], dtype=float)
        dt = np.diff(t)[:, None]
        # control points per piece: (pieces, 4, 2)
        self.control = np.stack([p[:-1], p[:-1] + v[:-1] * dt / 3, p[1:] - v[1:] * dt / 3, p[1:]], axis=1)

    def __call__(self, t) -> np.ndarray:
        t = np.atleast_1d(np.asarray(t, dtype=float))
        piece = np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, len(self.t) - 2)
        s = (t - self.t[piece]) / (self.t[piece + 1] - self.t[piece])
        b = bernstein(3, s)  # (m, 4)
        return np.einsum("mk,mkd->md", b, self.control[piece])

    def velocity(self, t) -> np.ndarray:
        t = np.atleast_1d(np.asarray(t, dtype=float))
        piece = np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, len(self.t) - 2)
        dt = self.t[piece + 1] - self.t[piece]
        s = (t - self.t[piece]) / dt
        c = self.control[piece]
        diff = 3 * (c[:, 1:] - c[:, :-1])  # derivative control points (m, 3, 2)
        return np.einsum("mk,mkd->md", bernstein(2, s), diff) / dt[:, None]
