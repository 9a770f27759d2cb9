"""Smooth scalar profiles on [0, 1] used to blend corrections in and out without velocity jumps."""

from __future__ import annotations

import numpy as np


def hermite_to_zero(x, value0, rate0):
    """Cubic that starts at value0 with slope rate0 (per unit x) and reaches 0 with zero slope at x = 1.

    Beyond x = 1 it stays 0. Shapes broadcast: x (n,), value0/rate0 (k,) -> (n, k).
    """
    x = np.clip(np.atleast_1d(np.asarray(x, dtype=float)), 0.0, 1.0)[:, None]
    h00 = 2 * x**3 - 3 * x**2 + 1
    h10 = x**3 - 2 * x**2 + x
    return h00 * np.asarray(value0) + h10 * np.asarray(rate0)


def hermite_segment(x, p0, v0, p1, v1):
    """Cubic Hermite from (p0, slope v0) at x = 0 to (p1, slope v1) at x = 1; x (n,), values (k,)."""
    x = np.atleast_1d(np.asarray(x, dtype=float))[:, None]
    h00 = 2 * x**3 - 3 * x**2 + 1
    h10 = x**3 - 2 * x**2 + x
    h01 = -2 * x**3 + 3 * x**2
    h11 = x**3 - x**2
    return h00 * p0 + h10 * v0 + h01 * p1 + h11 * v1


def smoothstep(x):
    """3x^2 - 2x^3 clipped to [0, 1]: zero slope at both ends."""
    x = np.clip(np.asarray(x, dtype=float), 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def smootherstep(x):
    """6x^5 - 15x^4 + 10x^3 clipped to [0, 1]: zero slope and curvature at both ends."""
    x = np.clip(np.asarray(x, dtype=float), 0.0, 1.0)
    return x**3 * (x * (6.0 * x - 15.0) + 10.0)


def plateau(x, rise: float):
    """0 at the ends, 1 on [rise, 1 - rise], joined by smoothsteps: the swing lift's shape.

    Near the ends it grows like x^2, so a lift scaled by it can always cover a foot point that
    leaves the ground along a parabola.
    """
    x = np.asarray(x, dtype=float)
    return smoothstep(x / rise) * smoothstep((1.0 - x) / rise)
