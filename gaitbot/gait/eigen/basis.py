"""Functional bases on [0, 1] for Li et al. 2009 section 4.1: evaluation, Gram matrix W and roughness penalty R.

A motion channel x(s) is represented as ``Phi(s) @ c``. Least squares with a roughness penalty
(Ramsay and Silverman ch. 5) minimises ``|x_hat - Phi c|^2 + lam * c^T R c`` with
``R = int Phi''(s)^T Phi''(s) ds``, so ``c = (Phi^T Phi + lam R)^-1 Phi^T x_hat`` (Li et al. 2009 eq. 3 when
lam = 0). ``W = int Phi(s)^T Phi(s) ds`` is the Gram matrix of eq. 10.

- ``FourierBasis``: for periodic cycles (Li et al. 2009: keeps the first and last poses continuous).
  Orthonormal on [0, 1]: 1, sqrt2 cos(2 pi k s), sqrt2 sin(2 pi k s); W = I, R diagonal.
- ``BSplineBasis``: for non-periodic motions; clamped cubic B-splines on equally spaced knots;
  W and R by Gauss-Legendre quadrature on each knot interval (exact for these polynomials).
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import BSpline


class FourierBasis:
    kind = "fourier"

    def __init__(self, n_basis: int) -> None:
        if n_basis < 1 or n_basis % 2 == 0:
            raise ValueError(f"a Fourier basis needs an odd number of functions (1 + 2 per harmonic), got {n_basis}")
        self.n_basis = n_basis
        self.harmonics = (n_basis - 1) // 2

    def evaluate(self, s, derivative: int = 0) -> np.ndarray:
        """(n, K) values (or the given derivative, per unit s) at points s (periodic with period 1)."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        out = np.empty((len(s), self.n_basis))
        out[:, 0] = 1.0 if derivative == 0 else 0.0
        for k in range(1, self.harmonics + 1):
            w = 2.0 * np.pi * k
            arg = w * s
            # d^n/ds^n of cos and sin: rotate the phase by n quarter turns
            shift = derivative * np.pi / 2.0
            scale = np.sqrt(2.0) * w**derivative
            out[:, 2 * k - 1] = scale * np.cos(arg + shift)
            out[:, 2 * k] = scale * np.sin(arg + shift)
        return out

    def gram(self) -> np.ndarray:
        return np.eye(self.n_basis)

    def penalty(self) -> np.ndarray:
        """int (d^2 phi / ds^2)^2: diag 0, (2 pi k)^4 (twice each)."""
        d = np.zeros(self.n_basis)
        for k in range(1, self.harmonics + 1):
            d[2 * k - 1] = d[2 * k] = (2.0 * np.pi * k) ** 4
        return np.diag(d)


class BSplineBasis:
    kind = "bspline"
    order = 4  # cubic

    def __init__(self, n_basis: int) -> None:
        if n_basis < self.order:
            raise ValueError(f"a cubic B-spline basis needs at least {self.order} functions, got {n_basis}")
        self.n_basis = n_basis
        inner = np.linspace(0.0, 1.0, n_basis - self.order + 2)
        self.knots = np.concatenate([[0.0] * (self.order - 1), inner, [1.0] * (self.order - 1)])
        self._breaks = inner

    def evaluate(self, s, derivative: int = 0) -> np.ndarray:
        s = np.clip(np.atleast_1d(np.asarray(s, dtype=float)), 0.0, 1.0)
        out = np.empty((len(s), self.n_basis))
        for k in range(self.n_basis):
            coef = np.zeros(self.n_basis)
            coef[k] = 1.0
            spline = BSpline(self.knots, coef, self.order - 1, extrapolate=False)
            values = spline(s, nu=derivative) if derivative else spline(s)
            out[:, k] = np.nan_to_num(values)
        return out

    def _quadrature(self, derivative: int) -> np.ndarray:
        x, w = np.polynomial.legendre.leggauss(self.order + 1)
        points, weights = [], []
        for a, b in zip(self._breaks, self._breaks[1:]):
            points.append(0.5 * (b - a) * x + 0.5 * (a + b))
            weights.append(0.5 * (b - a) * w)
        s, w = np.concatenate(points), np.concatenate(weights)
        # keep points strictly inside [0, 1] so the right end is not evaluated as 0
        values = self.evaluate(np.clip(s, 0.0, 1.0 - 1e-12), derivative)
        return values.T @ (values * w[:, None])

    def gram(self) -> np.ndarray:
        return self._quadrature(0)

    def penalty(self) -> np.ndarray:
        return self._quadrature(2)


def make_basis(kind: str, n_basis: int):
    if kind == "fourier":
        return FourierBasis(n_basis)
    if kind == "bspline":
        return BSplineBasis(n_basis)
    raise ValueError(f"unknown basis {kind!r} (allowed: fourier, bspline)")


def fit_coefficients(basis, s, values, roughness: float = 0.0) -> np.ndarray:
    """Penalised least squares (Li et al. eq. 3, with a roughness penalty): values (n,) or (n, d) -> (K,) or (K, d)."""
    phi = basis.evaluate(s)
    lhs = phi.T @ phi + roughness * basis.penalty()
    return np.linalg.solve(lhs, phi.T @ np.asarray(values, dtype=float))
