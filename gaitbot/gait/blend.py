"""Bernstein (Bezier) weighting of Boulic poses between steps of different length (Jing et al. 2015 eq. 14).

For the step from step length sl_i to sl_(i+1), m intermediate step lengths are solved for RV and
the m + 2 Boulic poses at the same phase are weighted by Bernstein polynomials of degree m + 1 in
the step's progress u. At u = 0 the pose is exactly the sl_i pose, at u = 1 exactly the sl_(i+1)
pose (the end-point property), so each heel strike keeps its own step length.

Speed-up, exact: in region A every keyframe has a fixed phase and a value affine in RV, and the
Hermite blend is linear in the keyframe values. Weights summing to one therefore make the
weighted pose equal to the Boulic pose at the weighted RV, sum_j B_j(u) rv_j. So region-A blends
cost one Hermite evaluation per joint, not m + 2 (tested against the direct sum).
"""

from __future__ import annotations

from math import comb

import numpy as np

from .boulic import REGION_A_MAX, hermite_periodic, keyframes_deg, toe_off_phase

_JOINTS = ("hip", "knee", "ankle")


def bernstein_weights(degree: int, u) -> np.ndarray:
    """B_{i,n}(u) = C(n, i) (1 - u)^(n - i) u^i for i = 0..n: shape (len(u), n + 1)."""
    u = np.atleast_1d(np.asarray(u, dtype=float))[:, None]
    i = np.arange(degree + 1)
    coefficients = np.array([comb(degree, k) for k in i], dtype=float)
    return coefficients * (1.0 - u) ** (degree - i) * u**i


class _AffineKeyframes:
    """Region-A keyframes of one joint: fixed phases, values = offset + slope * RV (degrees)."""

    def __init__(self, joint: str, toe_off: float) -> None:
        p0, v0 = keyframes_deg(0.0, toe_off)[joint]
        p1, v1 = keyframes_deg(0.25, toe_off)[joint]
        if not np.array_equal(p0, p1):
            raise AssertionError("region-A keyframe phases must not depend on RV")
        n = len(p0)
        # keyframes extended by one period on each side, so every phase in [0, 1) has a bracket
        self.p_ext = np.concatenate([p0[-1:] - 1.0, p0, p0[:1] + 1.0])
        index = np.concatenate([[n - 1], np.arange(n), [0]])
        self.offset, self.slope = v0[index], ((v1 - v0) / 0.25)[index]
        self.n = n

    def evaluate(self, phase, rv):
        """Angle (degrees) at phase(s) with per-sample RV(s)."""
        phase = np.asarray(phase, dtype=float) % 1.0
        i = np.minimum(np.searchsorted(self.p_ext, phase, side="right") - 1, self.n)
        p0, p1 = self.p_ext[i], self.p_ext[i + 1]
        s = (phase - p0) / (p1 - p0)
        h01 = s * s * (3.0 - 2.0 * s)
        v0 = self.offset[i] + self.slope[i] * rv
        v1 = self.offset[i + 1] + self.slope[i + 1] * rv
        return v0 + (v1 - v0) * h01


class BoulicBlend:
    """Leg angles of the Bernstein-weighted Boulic poses at the RVs ``rvs`` (in step order).

    ``leg(phase, u)`` returns one leg's hip, knee, ankle (radians, shape (n, 3)) at its own
    cycle phase, weighted at step progress u.
    """

    _affine_cache: dict[float, list[_AffineKeyframes]] = {}

    def __init__(self, rvs, cycle_s: float) -> None:
        self.rvs = np.array([float(r) for r in rvs])
        self.degree = len(self.rvs) - 1
        self.toe_off = toe_off_phase(cycle_s)
        self.region_a = bool(np.all(self.rvs <= REGION_A_MAX))
        if self.region_a:
            if self.toe_off not in self._affine_cache:
                self._affine_cache[self.toe_off] = [_AffineKeyframes(j, self.toe_off) for j in _JOINTS]
            self._affine = self._affine_cache[self.toe_off]

    def leg(self, phase, u) -> np.ndarray:
        phase = np.atleast_1d(np.asarray(phase, dtype=float))
        weights = bernstein_weights(self.degree, u)  # (n, m + 2)
        if self.region_a:
            rv = weights @ self.rvs
            return np.radians(np.stack([k.evaluate(phase, rv) for k in self._affine], axis=-1))
        return self.direct_sum(phase, u)

    def direct_sum(self, phase, u) -> np.ndarray:
        """eq. 14 as written: the weighted sum of the m + 2 Boulic poses (any region)."""
        phase = np.atleast_1d(np.asarray(phase, dtype=float))
        weights = bernstein_weights(self.degree, u)
        out = np.zeros(phase.shape + (3,))
        for j, rv in enumerate(self.rvs):
            key = keyframes_deg(float(rv), self.toe_off)
            for k, joint in enumerate(_JOINTS):
                out[:, k] += weights[:, j] * hermite_periodic(phase, *key[joint])
        return np.radians(out)
