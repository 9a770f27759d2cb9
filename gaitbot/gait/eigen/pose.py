"""Pose PCA (Li et al. 2009 section 3 (3), eq. 1), with the number of axes chosen for a robot.

The paper keeps the leading axes holding 95% of the pose variance (72 degrees of freedom down to
15). A walking robot has six, and the 5% left out is not noise: on the shipped biped's flat walks
the 95% rule keeps 3 axes, which move some joint of the examples by up to 10 degrees, put the
synthesised swing foot a centimetre lower and make short steps a third too long (README,
"Eigen-gaits"). So the rule here is the paper's with a floor in degrees: keep at least the axes
that hold ``variance`` of the pose variance, and more until projecting the examples' poses onto
the kept axes moves no joint by more than ``tolerance_deg`` (default 0.5 deg; ``inf`` gives the
paper's rule alone). Both numbers are reported, so a user sees what 95% would have cost.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PosePCA:
    """mean (D,), axes (D, d) U of eq. 1, eigenvalues (D,) of all axes (rad^2, descending),
    variance_dims (axes the variance rule alone keeps), residuals_deg (D,): the largest joint error
    the leading 1, 2, ..., D axes leave on the examples' poses (degrees)."""

    mean: np.ndarray
    axes: np.ndarray
    eigenvalues: np.ndarray
    variance_dims: int
    residuals_deg: np.ndarray

    @property
    def dims(self) -> int:
        return self.axes.shape[1]


def leading_count(eigenvalues: np.ndarray, share: float) -> int:
    """Smallest count whose eigenvalues hold at least ``share`` of the total (Li et al. 2009 eq. 11)."""
    total = eigenvalues.sum()
    if total <= 0:
        return 1
    cumulative = np.cumsum(eigenvalues) / total
    return int(min(len(eigenvalues), np.searchsorted(cumulative, share - 1e-12, side="left") + 1))


def largest_residual_deg(poses: np.ndarray, mean: np.ndarray, axes: np.ndarray) -> float:
    """Largest joint-angle change (degrees) that projecting ``poses`` (n, D) onto ``axes`` makes."""
    centred = poses - mean
    residual = centred - (centred @ axes) @ axes.T
    return float(np.degrees(np.abs(residual).max())) if residual.size else 0.0


def pose_pca(poses: np.ndarray, variance: float, tolerance_deg: float) -> PosePCA:
    """PCA of poses (n, D) in radians, axes chosen as the module docstring says."""
    mean = poses.mean(axis=0)
    eigenvalues, vectors = np.linalg.eigh(np.cov((poses - mean).T, bias=True))
    order = np.argsort(eigenvalues)[::-1]
    eigenvalues, vectors = np.clip(eigenvalues[order], 0.0, None), vectors[:, order]
    residuals = np.array([largest_residual_deg(poses, mean, vectors[:, :d]) for d in range(1, len(mean) + 1)])
    by_variance = leading_count(eigenvalues, variance)
    d = by_variance
    while d < len(eigenvalues) and residuals[d - 1] > tolerance_deg:
        d += 1
    return PosePCA(mean, vectors[:, :d], eigenvalues, by_variance, residuals)
