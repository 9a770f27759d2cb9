"""Kajita's ZMP preview control on the cart-table model, for x and y at once (docs/balance.md).

Cart-table (Kajita et al., "Biped walking pattern generation by using preview control of zero-moment
point", ICRA 2003): the centre of mass at a constant height z_c, ZMP p = x - (z_c / g) x''. State
X = [x, x', x''] per axis, input the CoM jerk u, period dt:

    X+ = A X + B u,  p = C X,  A = [[1, dt, dt^2/2], [0, 1, dt], [0, 0, 1]],
    B = [dt^3/6, dt^2/2, dt],  C = [1, 0, -z_c/g].

With the integral of the ZMP error s_k = sum_{i<=k} (p_i - r_i) and the future references known,
minimising sum Qe s^2 + R u^2 gives

    u_k = -K z_k + sum_{j=1..N} f_j r_{k+j},   z = [s; X],   K = (R + B~'PB~)^-1 B~'P A~,
    f_j = (R + B~'PB~)^-1 B~' ((A~ - B~K)')^(j-1) P e1,

P from the discrete algebraic Riccati equation (scipy.linalg.solve_discrete_are). The gains depend on
(z_c, dt, N, R) only and are computed once per robot and rate (cached). ``PreviewController.step`` is
the online form (one frame, O(N)); ``preview_offline`` runs the same recursion over a whole reference
as a linear filter (scipy.signal.lfilter, C speed).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.linalg import solve_discrete_are

GRAVITY_M_S2 = 9.81


@dataclass(frozen=True, eq=False)
class PreviewGains:
    """The integral gain k_sum, the state gains k_state (3,), the preview weights f (N,) and the discrete
    model (a, b, c) of one CoM height and period."""

    dt_s: float
    com_height_m: float
    k_sum: float
    k_state: np.ndarray
    f: np.ndarray
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray

    @property
    def horizon_frames(self) -> int:
        return len(self.f)

    def weight_share_within(self, frames: int) -> float:
        """Share of the (absolute) preview weight carried by the first ``frames`` future frames: how much
        of the preview a shorter horizon would lose (docs/balance.md, "Preview horizon")."""
        w = np.abs(self.f)
        return float(w[:frames].sum() / w.sum())


@lru_cache(maxsize=32)
def preview_gains(com_height_m: float, dt_s: float, horizon_frames: int, jerk_weight: float = 1e-6,
                  error_weight: float = 1.0) -> PreviewGains:
    """Solve the Riccati equation once for this CoM height (m), period (s) and horizon (frames)."""
    dt = dt_s
    a = np.array([[1.0, dt, dt * dt / 2], [0.0, 1.0, dt], [0.0, 0.0, 1.0]])
    b = np.array([dt ** 3 / 6, dt * dt / 2, dt])
    c = np.array([1.0, 0.0, -com_height_m / GRAVITY_M_S2])
    at = np.zeros((4, 4))
    at[0, 0] = 1.0
    at[0, 1:] = c @ a
    at[1:, 1:] = a
    bt = np.concatenate([[c @ b], b])[:, None]
    p = solve_discrete_are(at, bt, np.diag([error_weight, 0.0, 0.0, 0.0]), np.array([[jerk_weight]]))
    denom = float(jerk_weight + (bt.T @ p @ bt)[0, 0])
    k = (bt.T @ p @ at)[0] / denom
    closed = at - bt @ k[None, :]
    f = np.empty(horizon_frames)
    v = p[:, 0].copy()  # ((A~ - B~K)')^(j-1) P e1
    for j in range(horizon_frames):
        f[j] = float(bt[:, 0] @ v) / denom
        v = closed.T @ v
    return PreviewGains(dt, com_height_m, float(k[0]), k[1:].copy(), f, a, b, c)


class PreviewController:
    """Online preview control of the CoM in x and y: one ``step`` per frame.

    state: (3, 2) [position, velocity, acceleration] x [x, y]; error_sum: (2,) the integrated ZMP error."""

    def __init__(self, gains: PreviewGains, com_xy_m) -> None:
        self.gains = gains
        self.state = np.zeros((3, 2))
        self.state[0] = com_xy_m
        self.error_sum = np.zeros(2)

    def step(self, reference_now, reference_future) -> np.ndarray:
        """Advance one frame. reference_now: r_k (2,); reference_future: r_{k+1..k+N} (N, 2).
        Returns the CoM position (2,) at frame k + 1."""
        g = self.gains
        self.error_sum += g.c @ self.state - reference_now
        u = -g.k_sum * self.error_sum - g.k_state @ self.state + g.f @ reference_future
        self.state = g.a @ self.state + np.outer(g.b, u)
        return self.state[0].copy()


@lru_cache(maxsize=32)
def _transfer_functions(gains: PreviewGains):
    """The recursion as three single-input filters per axis (preview sum, reference, initial state)."""
    from scipy.signal import ss2tf

    b, c, ks, kx = gains.b, gains.c, gains.k_sum, gains.k_state
    m = np.zeros((4, 4))
    m[0, 0], m[0, 1:] = 1.0, c
    m[1:, 0] = -b * ks
    m[1:, 1:] = gains.a - np.outer(b, ks * c + kx)
    select = np.array([[0.0, 1.0, 0.0, 0.0]])
    out = []
    for z0 in (0.0, 1.0):  # the initial-state column is linear in x0: unit response, scaled later
        inputs = np.column_stack([np.r_[0.0, b], np.r_[-1.0, b * ks], np.array([0.0, z0, 0.0, 0.0])])
        out.append([ss2tf(m, inputs, select, np.zeros((1, 3)), input=i) for i in range(3)])
    return out[1]


def preview_offline(gains: PreviewGains, reference, com_xy0=None) -> np.ndarray:
    """CoM positions (n, 2) for a whole reference (n, 2), padded with its last value beyond its end;
    frame 0's state is at rest at com_xy0 (default: reference[0]).

    The recursion of PreviewController.step as a linear time-invariant filter: with w_k the error sum
    up to k - 1, Z_k = [w_k, x_k] evolves as Z_k+1 = M Z_k + N [P_k, r_k], P_k = sum_j f_j r_k+j (one
    correlation); the initial state enters as an impulse one frame before frame 0."""
    from scipy.signal import lfilter

    ref = np.asarray(reference, dtype=float)
    n, horizon = len(ref), gains.horizon_frames
    padded = np.concatenate([ref, np.repeat(ref[-1:], horizon, axis=0)])
    preview = np.lib.stride_tricks.sliding_window_view(padded[1:], horizon, axis=0)[:n] @ gains.f
    x0 = ref[0] if com_xy0 is None else np.asarray(com_xy0, dtype=float)
    (num_p, den_p), (num_r, den_r), (num_0, den_0) = _transfer_functions(gains)
    impulse = np.zeros(n + 1)
    impulse[0] = 1.0
    unit = lfilter(num_0[0], den_0, impulse)[1:]
    out = np.empty((n, 2))
    for axis in range(2):
        out[:, axis] = (lfilter(num_p[0], den_p, preview[:, axis]) + lfilter(num_r[0], den_r, ref[:, axis])
                        + x0[axis] * unit)
    return out


class FloatPreview:
    """PreviewController's recursion in plain floats, the preview sum given (the online walker's hot path:
    numpy costs microseconds a call whatever the array size, and the state is 2 x 3 numbers).

    ``step(rx, ry, px, py)``: the reference now (rx, ry) and its preview sum sum_j f_j r_{k+j} (px, py)
    (``preview_sums``); ``snapshot()`` / ``restore()``: the state as a tuple."""

    def __init__(self, gains: PreviewGains, com_xy_m) -> None:
        a, self.b, self.c = gains.a, tuple(float(v) for v in gains.b), tuple(float(v) for v in gains.c)
        if not (a[1, 0] == a[2, 0] == a[2, 1] == 0.0 and a[0, 0] == a[1, 1] == a[2, 2] == 1.0):
            raise ValueError("FloatPreview expects the cart-table's triple integrator")
        self.a01, self.a02, self.a12 = float(a[0, 1]), float(a[0, 2]), float(a[1, 2])
        self.k_sum, self.k = gains.k_sum, tuple(float(v) for v in gains.k_state)
        self.f = gains.f
        self.state = (float(com_xy_m[0]), 0.0, 0.0, float(com_xy_m[1]), 0.0, 0.0, 0.0, 0.0)

    def snapshot(self) -> tuple:
        return self.state

    def restore(self, state: tuple) -> None:
        self.state = state

    @property
    def com(self) -> tuple[float, float]:
        """The CoM position (x, y) at the current frame (before its step)."""
        return self.state[0], self.state[3]

    def preview_sums(self, padded, start: int, count: int) -> np.ndarray:
        """sum_j f_j r_{i+j}, j = 1..N, for i = start..start + count - 1 (count, 2) of a reference padded past
        its end."""
        n = len(self.f)
        if count == 1:
            return (self.f @ padded[start + 1:start + 1 + n])[None]
        part = padded[start + 1:start + count + n]
        return np.column_stack([np.correlate(part[:, 0], self.f), np.correlate(part[:, 1], self.f)])

    def step(self, rx: float, ry: float, px: float, py: float) -> None:
        x0, x1, x2, y0, y1, y2, ex, ey = self.state
        b0, b1, b2 = self.b
        c0, c1, c2 = self.c
        k0, k1, k2 = self.k
        ks, a01, a02, a12 = self.k_sum, self.a01, self.a02, self.a12
        ex += c0 * x0 + c1 * x1 + c2 * x2 - rx
        ey += c0 * y0 + c1 * y1 + c2 * y2 - ry
        ux = -ks * ex - (k0 * x0 + k1 * x1 + k2 * x2) + px
        uy = -ks * ey - (k0 * y0 + k1 * y1 + k2 * y2) + py
        self.state = (x0 + a01 * x1 + a02 * x2 + b0 * ux, x1 + a12 * x2 + b1 * ux, x2 + b2 * ux,
                      y0 + a01 * y1 + a02 * y2 + b0 * uy, y1 + a12 * y2 + b1 * uy, y2 + b2 * uy, ex, ey)
