"""Boulic's free-walking model (Jing et al. 2015 section 2.1; keyframes per docs/gait-model.md section 2).

Global level: relative velocity RV (speed / leg length) sets the cycle's relative length and
phase durations. Joint level: hip, knee and ankle angles over a leg's own phase, given by
keyframes joined with the zero-tangent cubic Hermite blend of Jing et al. 2015, Appendix A.
Everything here is vectorised over phase and, where it makes sense, over RV.
"""

from __future__ import annotations

import numpy as np

REGION_A_MAX = 0.5  # RV regions A = [0, 0.5), B = [0.5, 1.3), C = [1.3, 3.0]
REGION_B_MAX = 1.3
REGION_C_MAX = 3.0
TABLE2_CYCLE_S = 1.346  # Jing et al. 2015, Table 2: Dc, fixed for the step-length control


def relative_length(rv):
    """RL = 1.346 sqrt(RV): cycle length over leg length (Jing et al. 2015 eq. 1)."""
    return 1.346 * np.sqrt(rv)


def cycle_duration_s(rv):
    """Dc = RL / RV seconds (Jing et al. 2015 eq. 2) for a leg of length 1."""
    return relative_length(rv) / rv


def support_duration_s(cycle_s):
    """Ds = 0.752 Dc - 0.143 (Jing et al. 2015 eq. 3)."""
    return 0.752 * cycle_s - 0.143


def balance_duration_s(cycle_s):
    """Db = 0.248 Dc + 0.143 (Jing et al. 2015 eq. 4)."""
    return 0.248 * cycle_s + 0.143


def double_support_duration_s(cycle_s):
    """Dds = 0.252 Dc - 0.143 (Jing et al. 2015 eq. 5)."""
    return 0.252 * cycle_s - 0.143


def toe_off_phase(cycle_s: float = TABLE2_CYCLE_S) -> float:
    """Ds / Dc: the phase of a leg's toe-off (0.6458 with Table 2's Dc)."""
    return support_duration_s(cycle_s) / cycle_s


def keyframes_deg(rv: float, toe_off: float) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Keyframes (phases, degrees) of hip, knee and ankle at one RV, phases sorted in [0, 1).

    Region A scales with RV; B is constant; C moves with r = (RV - 1.3) / 1.7. At RV = 0.5 and
    1.3 neighbouring regions give the same curves (tested).
    """
    if rv < REGION_A_MAX:
        hip = [(0.5, -30 * rv), (0.9, 50 * rv)]
        knee = [(0.0, 3.0), (0.17, 3.0), (0.4, 3.0), (0.75, 140 * rv)]
        ankle = [(0.0, -3.0), (0.08, -30 * rv - 3), (0.5, 22 * rv - 3), (toe_off, -34 * rv - 3), (0.85, -3.0)]
    elif rv < REGION_B_MAX:
        hip = [(0.5, -15.0), (0.9, 25.0)]
        knee = [(0.0, 3.0), (0.17, 3.0), (0.4, 3.0), (0.75, 70.0)]
        ankle = [(0.0, -3.0), (0.08, -18.0), (0.5, 8.0), (toe_off, -20.0), (0.85, -3.0)]
    else:
        r = (min(rv, REGION_C_MAX) - REGION_B_MAX) / (REGION_C_MAX - REGION_B_MAX)
        hip = [(0.5, -15.0), (0.9, 25 + 6 * r), (0.9 + 0.2 * r, 25 + 5 * r)]
        knee = [(-0.03 * r, 3 + 3 * r), (0.17 - 0.05 * r, 3 + 22 * r), (0.4, 3.0), (0.75 - 0.05 * r, 70 - 5 * r)]
        ankle = [(0.0, 5 * r - 3), (0.08, 4 * r - 18), (0.5 - 0.1 * r, 8 - 3 * r), (toe_off, -20 - 8 * r),
                 (0.85, 5 * r - 3)]
    return {name: _sorted_wrapped(points) for name, points in (("hip", hip), ("knee", knee), ("ankle", ankle))}


def _sorted_wrapped(points) -> tuple[np.ndarray, np.ndarray]:
    phases = np.array([p for p, _ in points]) % 1.0
    values = np.array([v for _, v in points], dtype=float)
    order = np.argsort(phases, kind="stable")
    return phases[order], values[order]


def hermite_periodic(phase, key_phases: np.ndarray, key_values: np.ndarray):
    """Zero-tangent cubic Hermite blend between consecutive keyframes, wrapping at 1.0.

    theta(s) = theta_start (2s^3 - 3s^2 + 1) + theta_end (-2s^3 + 3s^2), s in [0, 1) between
    two keyframes (Jing et al. 2015 Appendix A). With a single keyframe the curve is constant.
    """
    phase = np.asarray(phase, dtype=float) % 1.0
    n = len(key_phases)
    # extend the keyframes by one period on each side so every phase has a bracket
    p_ext = np.concatenate([key_phases[-1:] - 1.0, key_phases, key_phases[:1] + 1.0])
    v_ext = np.concatenate([key_values[-1:], key_values, key_values[:1]])
    i = np.searchsorted(p_ext, phase, side="right") - 1
    i = np.clip(i, 0, n)
    p0, p1 = p_ext[i], p_ext[i + 1]
    v0, v1 = v_ext[i], v_ext[i + 1]
    span = np.where(p1 > p0, p1 - p0, 1.0)
    s = (phase - p0) / span
    return v0 * (2 * s**3 - 3 * s**2 + 1) + v1 * (-2 * s**3 + 3 * s**2)


def leg_angles_rad(rv: float, phase, cycle_s: float = TABLE2_CYCLE_S) -> np.ndarray:
    """Hip, knee and ankle flexion (radians) of one leg at its own phase(s): shape (..., 3)."""
    frames = keyframes_deg(rv, toe_off_phase(cycle_s))
    out = [hermite_periodic(phase, *frames[j]) for j in ("hip", "knee", "ankle")]
    return np.radians(np.stack(out, axis=-1))


def pose_rad(rv: float, phase, cycle_s: float = TABLE2_CYCLE_S) -> np.ndarray:
    """Both legs at cycle phase(s) t%: (..., 6) = left hip, knee, ankle, right hip, knee, ankle.

    The right leg runs half a cycle behind the left.
    """
    phase = np.asarray(phase, dtype=float)
    return np.concatenate([leg_angles_rad(rv, phase, cycle_s), leg_angles_rad(rv, phase + 0.5, cycle_s)], axis=-1)
