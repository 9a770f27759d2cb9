"""Bernstein (Bezier) weighting of Boulic poses between steps of different length (seed 000 eq. 14).

For the step from step length sl_i to sl_(i+1), m intermediate step lengths are solved for RV and
the m + 2 Boulic poses at the same phase are weighted by Bernstein polynomials of degree m + 1 in
the step's progress u. At u = 0 the pose is exactly the sl_i pose, at u = 1 exactly the sl_(i+1)
pose (the end-point property), so each heel strike keeps its own step length.
"""

from __future__ import annotations

from math import comb

import numpy as np

from .boulic import hermite_periodic, keyframes_deg, toe_off_phase

_JOINTS = ("hip", "knee", "ankle")


def bernstein_weights(degree: int, u) -> np.ndarray:
    """B_{i,n}(u) = C(n, i) (1 - u)^(n - i) u^i for i = 0..n: shape (len(u), n + 1)."""
    u = np.atleast_1d(np.asarray(u, dtype=float))[:, None]
    i = np.arange(degree + 1)
    coefficients = np.array([comb(degree, k) for k in i], dtype=float)
    return coefficients * (1.0 - u) ** (degree - i) * u**i


class BoulicBlend:
    """Leg angles of the Bernstein-weighted Boulic poses at the RVs ``rvs`` (in step order).

    ``leg(phase, u)`` returns one leg's hip, knee, ankle (radians, shape (n, 3)) at its own
    cycle phase, weighted at step progress u. Keyframes are built once per RV here, so
    evaluation is a few vectorised Hermite blends.
    """

    def __init__(self, rvs, cycle_s: float) -> None:
        self.rvs = tuple(float(r) for r in rvs)
        toe_off = toe_off_phase(cycle_s)
        self._frames = [keyframes_deg(rv, toe_off) for rv in self.rvs]
        self.degree = len(self.rvs) - 1

    def leg(self, phase, u) -> np.ndarray:
        phase = np.atleast_1d(np.asarray(phase, dtype=float))
        weights = bernstein_weights(self.degree, u)  # (n, m + 2)
        out = np.zeros(phase.shape + (3,))
        for j, frames in enumerate(self._frames):
            w = weights[:, j]
            if not np.any(w):
                continue
            for k, joint in enumerate(_JOINTS):
                out[:, k] += w * hermite_periodic(phase, *frames[joint])
        return np.radians(out)
