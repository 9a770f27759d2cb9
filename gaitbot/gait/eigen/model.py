"""Eigen-gaits (Li et al. 2009): fit a functional-PCA model to example cycles, save/load it, synthesise cycles.

Fit (``fit_model``), following Li et al. 2009:
1. each cycle is resampled to ``samples`` frames (section 3 (2)) and DTW-aligned to a reference,
   the example whose label is the median (section 3 (1)); the warps are kept (see align.py);
2. PCA of all aligned poses; the leading axes U explaining ``pose_variance`` (default 95%) are
   kept (eq. 1), and more until no example pose moves by more than ``pose_tolerance_deg``
   (default 0.5 deg) when projected on them (pose.py says why);
3. each reduced channel of each example is fitted by penalised least squares in a Fourier basis
   (periodic cycles) or a B-spline basis (section 4.1, eq. 3);
4. functional PCA of the coefficient vectors: ``N^-1 C^T C W b = lambda b`` (eq. 10), W the
   basis Gram matrix (block diagonal over the reduced channels). Solved in its symmetric form
   ``L^T (N^-1 C^T C) L u = lambda u`` with W = L L^T and b = L^-T u, so the eigen-motions
   ``xi_i(s) = Phi(s) b_i`` are orthonormal in L2 and an example's score is
   ``alpha_i = b_i^T W (c - c_mean)``. The leading eigen-motions explaining more than
   ``motion_variance`` (default 95%, eq. 11) are kept.

Synthesis (section 5): the reduced motion ``mean(s) + sum alpha_i xi_i(s)`` (eq. 12), back-projected
``pose_mean + x U^T`` (eq. 14). Coefficients come directly, from a label (a polynomial regression
of the examples' scores, warps, durations and right-strike phases on their step length), or from a
required pose p at a time t' by ``alpha = alpha0 + pinv(Delta) (p - x(t'; alpha0))`` with
``Delta = [xi_1(t') ... xi_m(t')]`` (eq. 13, applied to the change from a base motion alpha0 so
that the least-norm solution stays near the base walk rather than near the mean).

Joints: a model learns the joints its examples hold, the robot's walker's joints (legs.py: the six
pitch joints of a pitch-only robot, all twelve of a robot whose legs roll), and keeps their names; it
learns no root channel: the root of a synthesised walk comes from foot contact (legs.py). File version
2 stores the joint names, the root axes and (for 3D legs) the body geometry; a version 1 file is the six
pitch joints with a planar root.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gaitbot.errors import UserError
from gaitbot.gait.npz_file import NpzProblem, numeric, read_npz

from ..body import BodyGeometry
from ..geometry import LegGeometry
from ..joints import LEG_JOINTS, PITCH_JOINTS, is_leg_joint
from .align import align_to_reference, resample_cycle, sample_phases
from .basis import fit_coefficients, make_basis
from .example_cycles import ExampleCycle
from .legs import PlanarLegs, SpatialLegs
from .pose import leading_count, pose_pca

MODEL_KIND = "gaitbot-eigen-gait"
MODEL_VERSION = 2
#: Versions this gaitbot reads: 1 (six pitch joints, no names stored) and 2 (joint names and root axes).
READ_VERSIONS = (1, 2)
#: Root axes a model's walks move in, each with the joints its legs have (legs.py).
ROOT_AXES = {"xz": PITCH_JOINTS, "xyz": LEG_JOINTS}
#: BodyGeometry's fields in the order the file's ``body_geometry`` holds them.
BODY_GEOMETRY_FIELDS = ("thigh_m", "shank_m", "foot_m", "foot_width_m", "hip_width_m", "ankle_height_m",
                        "heel_back_m", "sole_outward_m", "hip_below_root_m")


#: The largest roughness penalty a fit takes (beyond it every motion is a straight line anyway).
MAX_ROUGHNESS = 1e6


class EigenModelError(UserError, ValueError):
    """Bad input to fitting or synthesis (too few examples, unreachable pose, ...): one line for people."""


@dataclass(frozen=True)
class FitOptions:
    samples: int = 100
    basis: str = "fourier"
    n_basis: int = 31
    roughness: float = 0.0
    pose_variance: float = 0.95
    pose_tolerance_deg: float = 0.5  # inf: the paper's variance rule alone
    motion_variance: float = 0.95
    components: int | None = None  # fixed number of eigen-motions (overrides motion_variance)
    align: str = "dtw"  # or "none"
    dtw_band: float = 0.1
    label_degree: int = 2

    def __post_init__(self) -> None:
        if not 8 <= self.samples <= MODEL_LIMITS["samples"]:
            raise EigenModelError(f"samples must be 8..{MODEL_LIMITS['samples']}, got {self.samples}")
        if self.basis not in ("fourier", "bspline"):
            raise EigenModelError(f"basis must be fourier or bspline, got {self.basis!r}")
        if not (1 <= self.n_basis <= self.samples):
            raise EigenModelError(f"n_basis must be from 1 to samples ({self.samples}), got {self.n_basis}")
        if self.basis == "fourier" and self.n_basis % 2 == 0:
            raise EigenModelError(f"a Fourier basis needs an odd n_basis (1 + 2 per harmonic), got {self.n_basis}")
        for name in ("pose_variance", "motion_variance"):
            v = getattr(self, name)
            if not (0.0 < v <= 1.0):
                raise EigenModelError(f"{name} must be in (0, 1], got {v}")
        if not 0 <= self.roughness <= MAX_ROUGHNESS:
            raise EigenModelError(f"roughness must be 0..{MAX_ROUGHNESS:g}, got {self.roughness}")
        if not self.pose_tolerance_deg >= 0:
            raise EigenModelError(f"pose_tolerance_deg must be 0 or more degrees (inf: none), got {self.pose_tolerance_deg}")
        if self.roughness < 0:
            raise EigenModelError(f"roughness must be 0 or more, got {self.roughness}")
        if self.align not in ("dtw", "none"):
            raise EigenModelError(f"align must be dtw or none, got {self.align!r}")
        if not 0 <= self.label_degree <= 10:
            raise EigenModelError(f"label_degree must be 0..10, got {self.label_degree}")
        if self.components is not None and not 1 <= self.components <= MODEL_LIMITS["components"]:
            raise EigenModelError(f"components must be 1..{MODEL_LIMITS['components']}, got {self.components}")


@dataclass(frozen=True)
class EigenGaitModel:
    """Everything needed to synthesise; arrays are saved as they are in the ``.npz``."""

    basis_kind: str
    n_basis: int
    samples: int
    periodic: bool
    roughness: float
    pose_mean: np.ndarray  # (J,) rad, one per joint of ``joints``
    pose_axes: np.ndarray  # (J, d) U of eq. 1
    pose_eigenvalues: np.ndarray  # (J,) all pose PCA eigenvalues (rad^2)
    coef_mean: np.ndarray  # (d, K) mean function's coefficients per reduced channel
    eigen_coefs: np.ndarray  # (M, d, K) every eigen-motion with a nonzero eigenvalue
    eigenvalues: np.ndarray  # (M,)
    n_components: int  # m', the eigen-motions kept
    scores: np.ndarray  # (N, M) examples' coefficients
    labels: np.ndarray  # (N,) step length of each example, metres
    warp_coefs: np.ndarray  # (N, K) h(s) - s of each example (the DTW warp)
    durations_s: np.ndarray  # (N,)
    right_strike_phases: np.ndarray  # (N,) in real (unwarped) cycle phase
    label_degree: int
    geometry: LegGeometry
    rate_hz: float
    sources: tuple = field(default_factory=tuple)
    pose_variance_dims: int = 0  # pose axes the variance rule alone would keep (0: not recorded)
    pose_residuals_deg: np.ndarray | None = None  # (J,) largest joint error of the examples with 1..J pose axes
    robot: str = ""  # the robot the examples were walked for (its config's name); "" in files that predate it
    joints: tuple = PITCH_JOINTS  # the joint of each pose column (canonical order, gaitbot.gait.joints)
    root_axes: str = "xz"  # the root's axes a synthesised walk moves in, all from foot contact (legs.py)
    body_geometry: BodyGeometry | None = None  # the 3D leg (root_axes "xyz"): the contact rule's geometry

    def __post_init__(self) -> None:
        if self.root_axes not in ROOT_AXES or tuple(self.joints) != ROOT_AXES[self.root_axes]:
            raise ValueError(f"root axes {self.root_axes!r} go with the joints {ROOT_AXES.get(self.root_axes)}, "
                             f"got {self.joints}")
        if (self.root_axes == "xyz") != (self.body_geometry is not None):
            raise ValueError("a model of 3D legs (root axes xyz) needs their body geometry, and only it")
        if self.pose_mean.shape != (len(self.joints),):
            raise ValueError(f"pose_mean has shape {self.pose_mean.shape}, expected ({len(self.joints)},)")

    @property
    def legs(self):
        """The legs the model's walks stand on (legs.py); a planar robot whose root sits above its hips
        gets its lift from its config (app/eigen.py)."""
        if self.root_axes == "xyz":
            return SpatialLegs(self.body_geometry)
        return PlanarLegs(self.geometry)

    # -- basic evaluation -------------------------------------------------------------------
    @property
    def basis(self):
        return make_basis(self.basis_kind, self.n_basis)

    @property
    def variance_explained(self) -> np.ndarray:
        return self.eigenvalues / self.eigenvalues.sum()

    @property
    def pose_dims(self) -> int:
        return self.pose_axes.shape[1]

    def reduced(self, s, alpha) -> np.ndarray:
        """Reduced motion (n, d) at phases s for coefficients alpha (first len(alpha) eigen-motions)."""
        alpha = np.asarray(alpha, dtype=float)
        coefs = self.coef_mean + np.tensordot(alpha, self.eigen_coefs[:len(alpha)], axes=1)
        return self.basis.evaluate(s) @ coefs.T

    def poses(self, s, alpha) -> np.ndarray:
        """Joint angles (n, J) in radians at aligned phases s (eq. 12 then eq. 14), columns as ``joints``."""
        return self.pose_mean + self.reduced(s, alpha) @ self.pose_axes.T

    def eigen_motion(self, s, i: int) -> np.ndarray:
        """xi_i(s) back in joint space without the mean: (n, J) radians per unit coefficient."""
        return (self.basis.evaluate(s) @ self.eigen_coefs[i].T) @ self.pose_axes.T

    # -- labels ------------------------------------------------------------------------------
    def _regress(self, values: np.ndarray, label: float) -> np.ndarray:
        degree = min(self.label_degree, len(np.unique(self.labels)) - 1)
        centre, scale = self.labels.mean(), max(np.ptp(self.labels), 1e-12)
        x = (self.labels - centre) / scale
        design = np.vander(x, degree + 1)
        coef, *_ = np.linalg.lstsq(design, values.reshape(len(x), -1), rcond=None)
        row = np.vander(np.atleast_1d((label - centre) / scale), degree + 1)
        return (row @ coef).reshape(values.shape[1:])

    def label_range(self) -> tuple[float, float]:
        return float(self.labels.min()), float(self.labels.max())

    def coefficients_for(self, step_length_m: float, components: int | None = None) -> np.ndarray:
        m = self.n_components if components is None else components
        return self._regress(self.scores[:, :m], step_length_m)

    def timing_for(self, step_length_m: float):
        """(duration_s, warp coefficients, right-strike phase) at a label."""
        return (float(self._regress(self.durations_s, step_length_m)), self._regress(self.warp_coefs, step_length_m),
                float(self._regress(self.right_strike_phases, step_length_m)))

    def warp(self, s, warp_coefs) -> np.ndarray:
        """Real cycle phase h(s) of aligned phase s."""
        s = np.asarray(s, dtype=float)
        return s + self.basis.evaluate(s) @ warp_coefs

    def aligned_phase(self, phase, warp_coefs) -> np.ndarray:
        """Inverse warp: aligned phase s of real cycle phase (monotone interpolation on a fine grid)."""
        grid = np.linspace(0.0, 1.0, 20 * self.samples + 1)
        h = np.maximum.accumulate(self.warp(grid, warp_coefs))
        h = (h - h[0]) / (h[-1] - h[0])
        return np.interp(phase, h, grid)

    # -- pose constraint (eq. 13) -------------------------------------------------------------
    def through_pose(self, pose_rad, s_prime: float, alpha0) -> tuple[np.ndarray, np.ndarray]:
        """Coefficients whose motion passes through ``pose_rad`` (J,) at aligned phase s', nearest alpha0.

        Returns (alpha, miss_rad (J,)): the joint-space difference left (the part of the pose outside
        what the model's pose axes and eigen-motions can reach at s')."""
        alpha0 = np.asarray(alpha0, dtype=float)
        m = len(alpha0)
        p = (np.asarray(pose_rad, dtype=float) - self.pose_mean) @ self.pose_axes
        phi = self.basis.evaluate([s_prime])[0]
        delta = np.stack([self.eigen_coefs[i] @ phi for i in range(m)], axis=1)  # (d, m)
        residual = p - self.reduced([s_prime], alpha0)[0]
        alpha = alpha0 + np.linalg.pinv(delta) @ residual
        miss = np.asarray(pose_rad) - self.poses([s_prime], alpha)[0]
        return alpha, miss

    # -- file --------------------------------------------------------------------------------
    def save(self, path: str | Path) -> None:
        g = self.geometry
        body = {} if self.body_geometry is None else {
            "body_geometry": np.array([getattr(self.body_geometry, f) for f in BODY_GEOMETRY_FIELDS])}
        np.savez(Path(path), kind=np.array(MODEL_KIND), version=np.array(MODEL_VERSION),
                 basis_kind=np.array(self.basis_kind), n_basis=self.n_basis, samples=self.samples,
                 periodic=self.periodic, roughness=self.roughness, pose_mean=self.pose_mean,
                 pose_axes=self.pose_axes, pose_eigenvalues=self.pose_eigenvalues, coef_mean=self.coef_mean,
                 eigen_coefs=self.eigen_coefs, eigenvalues=self.eigenvalues, n_components=self.n_components,
                 scores=self.scores, labels=self.labels, warp_coefs=self.warp_coefs, durations_s=self.durations_s,
                 right_strike_phases=self.right_strike_phases, label_degree=self.label_degree,
                 geometry=np.array([g.thigh, g.shank, g.foot, g.hip_width, g.ankle_height, g.heel_back]),
                 rate_hz=self.rate_hz, sources=np.array([str(s) for s in self.sources], dtype=str),
                 pose_variance_dims=self.pose_variance_dims, robot=np.array(self.robot),
                 pose_residuals_deg=np.full(0, np.nan) if self.pose_residuals_deg is None else self.pose_residuals_deg,
                 joints=np.array(self.joints, dtype=str), root_axes=np.array(self.root_axes), **body)

    @classmethod
    def load(cls, path: str | Path) -> "EigenGaitModel":
        """Read a model written by ``save``; every array is checked (kind, shape, finite values, sizes within
        MODEL_LIMITS) before use, and any problem is one EigenModelError naming the file and the array."""
        path = Path(path)
        if not path.exists():
            raise EigenModelError(f"{path}: no such file")
        try:
            arrays = read_npz(path)
        except OSError as exc:
            raise EigenModelError(f"{path}: cannot read ({exc.strerror or exc})") from None
        except NpzProblem as exc:
            raise EigenModelError(f"{path}: not a readable eigen-gait model ({exc})") from None
        if "kind" not in arrays or arrays["kind"].dtype.kind != "U" or str(arrays["kind"]) != MODEL_KIND:
            raise EigenModelError(f"{path}: not an eigen-gait model (made by `gaitbot eigen fit`)")
        try:
            return cls._from_arrays(arrays)
        except NpzProblem as exc:
            raise EigenModelError(f"{path}: {exc}") from None

    @classmethod
    def _from_arrays(cls, d: dict[str, np.ndarray]) -> "EigenGaitModel":
        """The model of a file's arrays, each checked before it is used (NpzProblem names the array)."""
        a = _ModelArrays(d)
        version = a.whole("version", 0, 10**6)
        if version not in READ_VERSIONS:
            raise NpzProblem(f"model version {version}, this gaitbot reads {', '.join(map(str, READ_VERSIONS))}")
        joints, root_axes, body_geometry = _joints_and_legs(d, version)
        basis = _basis_fields(a)
        motion = _motion_fields(a, len(joints), basis["n_basis"])
        examples = _example_fields(a, len(joints), motion["scores"].shape[0])
        dims, m, n = motion["pose_axes"].shape[1], motion["eigen_coefs"].shape[0], motion["scores"].shape[0]
        return cls(**basis, **motion, **examples, periodic=bool(numeric(d, "periodic", 0)),
                   pose_mean=a.shaped("pose_mean", (len(joints),)),
                   pose_eigenvalues=a.shaped("pose_eigenvalues", (len(joints),)),
                   coef_mean=a.shaped("coef_mean", (dims, basis["n_basis"])), eigenvalues=a.shaped("eigenvalues", (m,)),
                   n_components=a.whole("n_components", 1, m),
                   warp_coefs=a.shaped("warp_coefs", (n, basis["n_basis"])),
                   label_degree=a.whole("label_degree", 0, 10), robot=a.text("robot") if "robot" in d else "",
                   joints=joints, root_axes=root_axes, body_geometry=body_geometry)


class _ModelArrays:
    """A model file's arrays, read one at a time with the check its use needs."""

    def __init__(self, arrays: dict[str, np.ndarray]) -> None:
        self.d = arrays

    def whole(self, key: str, low: int, high: int) -> int:
        value = numeric(self.d, key, 0)
        if value != np.floor(value) or not low <= value <= high:
            raise NpzProblem(f"array {key!r} must be a whole number {low}..{high}, got {float(value):g}")
        return int(value)

    def text(self, key: str) -> str:
        if key not in self.d or self.d[key].dtype.kind != "U" or self.d[key].ndim != 0:
            raise NpzProblem(f"array {key!r} must be one piece of text")
        return str(self.d[key])

    def shaped(self, key: str, shape: tuple, finite: bool = True) -> np.ndarray:
        value = numeric(self.d, key, len(shape), finite=finite)
        if value.shape != shape:
            raise NpzProblem(f"array {key!r} has shape {value.shape}, expected {shape}")
        return value


def _basis_fields(a: _ModelArrays) -> dict:
    """The basis the model's curves are written in: its kind, size, samples per cycle and roughness."""
    limits = MODEL_LIMITS
    basis_kind = a.text("basis_kind")
    if basis_kind not in ("fourier", "bspline"):
        raise NpzProblem(f"array 'basis_kind' must be fourier or bspline, got {basis_kind!r}")
    samples = a.whole("samples", 8, limits["samples"])
    n_basis = a.whole("n_basis", 1, min(samples, limits["n_basis"]))
    if basis_kind == "fourier" and n_basis % 2 == 0:
        raise NpzProblem(f"array 'n_basis': a Fourier basis needs an odd number, got {n_basis}")
    roughness = float(numeric(a.d, "roughness", 0))
    if not 0 <= roughness <= MAX_ROUGHNESS:
        raise NpzProblem(f"array 'roughness' must be 0..{MAX_ROUGHNESS:g}, got {roughness:g}")
    return {"basis_kind": basis_kind, "n_basis": n_basis, "samples": samples, "roughness": roughness}


def _motion_fields(a: _ModelArrays, n_joints: int, n_basis: int) -> dict:
    """The pose axes, the eigen-motions and the examples' scores on them (their shapes fix d, M and N)."""
    limits = MODEL_LIMITS
    axes = numeric(a.d, "pose_axes", 2)
    dims = axes.shape[1]
    if axes.shape[0] != n_joints or not 1 <= dims <= n_joints:
        raise NpzProblem(f"array 'pose_axes' has shape {axes.shape}, expected ({n_joints}, d) with d "
                         f"1..{n_joints} (one row per joint)")
    if not np.any(axes):
        raise NpzProblem("array 'pose_axes' is all zeros: no pose axis to synthesise along")
    eigen_coefs = numeric(a.d, "eigen_coefs", 3)
    m = eigen_coefs.shape[0]
    if eigen_coefs.shape[1:] != (dims, n_basis) or not 1 <= m <= limits["components"]:
        raise NpzProblem(f"array 'eigen_coefs' has shape {eigen_coefs.shape}, expected (M, {dims}, {n_basis}) "
                         f"with M 1..{limits['components']}")
    scores = numeric(a.d, "scores", 2)
    n = scores.shape[0]
    if scores.shape[1] != m or not 1 <= n <= limits["examples"]:
        raise NpzProblem(f"array 'scores' has shape {scores.shape}, expected (N, {m}) with N 1..{limits['examples']}")
    return {"pose_axes": axes, "eigen_coefs": eigen_coefs, "scores": scores}


def _example_fields(a: _ModelArrays, n_joints: int, n: int) -> dict:
    """The leg, the frame rate, the example files and what the fit measured of each example."""
    d = a.d
    geometry = a.shaped("geometry", (6,))
    if not (np.all(geometry[:4] > 0) and np.all(geometry[4:] >= 0) and np.all(geometry <= 2.0)):
        raise NpzProblem("array 'geometry' must hold thigh, shank, foot, hip width (positive), ankle height and "
                         "heel back (0 or more), each at most 2 m")
    rate_hz = float(numeric(d, "rate_hz", 0))
    if not 1.0 <= rate_hz <= 1000.0:
        raise NpzProblem(f"array 'rate_hz' must be a frame rate of 1..1000 Hz, got {rate_hz:g}")
    if "sources" not in d:
        raise NpzProblem("missing array 'sources'")
    sources = d["sources"]
    if sources.dtype.kind not in "U" or sources.ndim != 1:
        raise NpzProblem("array 'sources' must be a list of file names (text)")
    residuals = d.get("pose_residuals_deg")
    if residuals is not None:
        residuals = numeric(d, "pose_residuals_deg", 1, finite=False)
        if residuals.shape not in ((0,), (n_joints,)):
            raise NpzProblem(f"array 'pose_residuals_deg' has shape {residuals.shape}, expected ({n_joints},)")
    variance_dims = a.whole("pose_variance_dims", 0, n_joints) if "pose_variance_dims" in d else 0
    durations = a.shaped("durations_s", (n,))
    if not np.all((durations >= 0.2) & (durations <= 10.0)):
        raise NpzProblem("array 'durations_s' must hold cycle durations of 0.2..10 s")
    labels = a.shaped("labels", (n,))
    if not np.all((labels >= 0) & (labels <= 2.0)):
        raise NpzProblem("array 'labels' must hold step lengths of 0..2 m")
    phases = a.shaped("right_strike_phases", (n,))
    if not np.all((phases > 0) & (phases < 1)):
        raise NpzProblem("array 'right_strike_phases' must hold phases between 0 and 1")
    return {"geometry": LegGeometry(*map(float, geometry)), "rate_hz": rate_hz,
            "sources": tuple(str(x) for x in sources), "pose_variance_dims": variance_dims,
            "pose_residuals_deg": residuals, "durations_s": durations, "labels": labels,
            "right_strike_phases": phases}


def _joints_and_legs(d: dict[str, np.ndarray], version: int) -> tuple[tuple, str, BodyGeometry | None]:
    """The joint names, root axes and body geometry of a model file (version 1: the six pitch joints)."""
    if version == 1:
        return PITCH_JOINTS, "xz", None
    for key in ("joints", "root_axes"):
        if key not in d:
            raise NpzProblem(f"missing array {key!r} (a version {version} model names its joints and root axes)")
    raw = d["joints"]
    if raw.dtype.kind != "U" or raw.ndim != 1 or not 1 <= len(raw) <= len(LEG_JOINTS):
        raise NpzProblem(f"array 'joints' must be a list of 1 to {len(LEG_JOINTS)} joint names")
    joints = tuple(str(name) for name in raw)
    unknown = [name for name in joints if not is_leg_joint(name)]
    if unknown:
        raise NpzProblem(f"array 'joints' names {unknown[0][:40]!r}, not a leg joint gaitbot knows")
    root = d["root_axes"]
    if root.dtype.kind != "U" or root.ndim != 0 or str(root) not in ROOT_AXES:
        raise NpzProblem(f"array 'root_axes' must be one of {', '.join(ROOT_AXES)}")
    root_axes = str(root)
    if joints != ROOT_AXES[root_axes]:
        raise NpzProblem(f"array 'joints': a model whose root moves in {root_axes} learns "
                         f"{', '.join(ROOT_AXES[root_axes])} (in that order), got {', '.join(joints)}")
    if root_axes == "xz":
        return joints, root_axes, None
    body = numeric(d, "body_geometry", 1)
    if body.shape != (len(BODY_GEOMETRY_FIELDS),):
        raise NpzProblem(f"array 'body_geometry' has shape {body.shape}, expected ({len(BODY_GEOMETRY_FIELDS)},)")
    values = dict(zip(BODY_GEOMETRY_FIELDS, map(float, body)))
    positive = ("thigh_m", "shank_m", "foot_m", "foot_width_m", "hip_width_m")
    if not (all(0 < values[f] <= 2.0 for f in positive) and all(abs(v) <= 2.0 for v in values.values())
            and all(values[f] >= 0 for f in ("ankle_height_m", "heel_back_m", "hip_below_root_m"))):
        raise NpzProblem("array 'body_geometry' must hold thigh, shank, foot, foot width, hip width (positive), "
                         "ankle height, heel back, hip below root (0 or more) and sole outward, each within 2 m")
    return joints, root_axes, BodyGeometry(**values)


#: Sizes a model file may claim (a fitted model is far inside them): samples per cycle, basis functions,
#: eigen-motions and example cycles. Beyond them synthesis would allocate what the file asks, not what a walk needs.
MODEL_LIMITS = {"samples": 2000, "n_basis": 401, "components": 1000, "examples": 10_000}


def is_model_file(path: str | Path) -> bool:
    """True for an ``.npz`` written by ``EigenGaitModel.save`` (plot dispatches on this)."""
    path = Path(path)
    if not path.is_file():
        return False
    try:
        arrays = read_npz(path, only=("kind",))  # every header checked first: a hostile file is not loaded
    except (OSError, NpzProblem):
        return False
    return "kind" in arrays and str(arrays["kind"]) == MODEL_KIND


def fit_model(examples: list[ExampleCycle], geometry: LegGeometry, rate_hz: float,
              options: FitOptions = FitOptions(), periodic: bool = True, robot: str = "",
              on_progress=None, legs=None) -> EigenGaitModel:
    """Li et al. 2009 sections 3 and 4 on example cycles (see the module docstring). ``geometry`` is the leg that
    walked the examples and ``robot`` the robot they are for: the model keeps both, and synthesis for
    another leg or robot is refused (app/eigen.py). ``legs`` (legs.py; default the planar legs of
    ``geometry``) says which joints the cycles' columns are and how the root follows them. ``on_progress(k,
    n)``, if given, is told as each of the n example cycles is aligned (the time-consuming part: dynamic time
    warping)."""
    legs = PlanarLegs(geometry) if legs is None else legs
    n = len(examples)
    if n < 2:
        raise EigenModelError(f"functional PCA needs at least 2 example cycles, got {n}")
    widths = {e.angles_rad.shape[1] for e in examples}
    if widths != {len(legs.joints)}:
        raise EigenModelError(f"the example cycles hold {', '.join(map(str, sorted(widths)))} joints; "
                              f"these legs have {len(legs.joints)} ({', '.join(legs.joints)})")
    if options.components is not None and not (1 <= options.components <= n - 1):
        raise EigenModelError(f"{options.components} eigen-motions requested, but {n} example cycles give at most "
                              f"{n - 1}; add examples or ask for fewer components")
    labels = np.array([e.step_length_m for e in examples])
    distinct = len(np.unique(np.round(labels, 9)))
    if distinct < 2:
        raise EigenModelError(f"the examples have {distinct} distinct step length(s); the label regression needs "
                              f"at least 2 (walks at different step lengths)")
    phases = sample_phases(options.samples, periodic)
    cycles = [resample_cycle(e.angles_rad, options.samples, periodic) for e in examples]
    reference = cycles[int(np.argsort(labels)[n // 2])]
    aligned, warps = [], []
    for k, c in enumerate(cycles, start=1):
        if options.align == "dtw":
            a, h = align_to_reference(reference, c, options.dtw_band, periodic)
        else:
            a, h = c, phases.copy()
        aligned.append(a)
        warps.append(h)
        if on_progress is not None:
            on_progress(k, n)
    aligned = np.array(aligned)  # (N, S, J)

    # pose PCA (eq. 1; pose.py)
    pose = pose_pca(aligned.reshape(-1, aligned.shape[-1]), options.pose_variance, options.pose_tolerance_deg)
    d, axes, pose_mean = pose.dims, pose.axes, pose.mean
    reduced = (aligned - pose_mean) @ axes  # (N, S, d)

    # functional representation (eq. 3, with the roughness penalty)
    basis = make_basis(options.basis, options.n_basis)
    coefs = np.array([fit_coefficients(basis, phases, r, options.roughness).T for r in reduced])  # (N, d, K)
    warp_coefs = np.array([fit_coefficients(basis, phases, h - phases, options.roughness) for h in warps])

    # functional PCA (eq. 10)
    K = basis.n_basis
    gram = np.kron(np.eye(d), basis.gram())
    chol = np.linalg.cholesky(gram)
    coef_mean = coefs.mean(axis=0)
    centred = (coefs - coef_mean).reshape(n, d * K)
    _, sing, vt = np.linalg.svd(centred @ chol, full_matrices=False)
    eigenvalues = sing**2 / n
    keep = eigenvalues > eigenvalues[0] * 1e-12 if eigenvalues[0] > 0 else np.zeros_like(eigenvalues, bool)
    if not keep.any():
        raise EigenModelError("the example cycles are all the same: nothing varies, no eigen-motion to find")
    b = np.linalg.solve(chol.T, vt[keep].T).T  # (M, dK)
    eigenvalues = eigenvalues[keep]
    scores = centred @ gram @ b.T  # (N, M)
    if options.components is not None:
        if options.components > len(eigenvalues):
            raise EigenModelError(f"{options.components} eigen-motions requested, but the {n} example cycles vary "
                                  f"in only {len(eigenvalues)} independent ways")
        m = options.components
    else:
        m = leading_count(eigenvalues, options.motion_variance)
    return EigenGaitModel(
        basis_kind=options.basis, n_basis=K, samples=options.samples, periodic=periodic, roughness=options.roughness,
        pose_mean=pose_mean, pose_axes=axes, pose_eigenvalues=pose.eigenvalues, coef_mean=coef_mean,
        eigen_coefs=b.reshape(-1, d, K), eigenvalues=eigenvalues, n_components=m, scores=scores, labels=labels,
        warp_coefs=warp_coefs, durations_s=np.array([e.duration_s for e in examples]),
        right_strike_phases=np.array([e.right_strike_phase for e in examples]), label_degree=options.label_degree,
        geometry=geometry, rate_hz=float(rate_hz), sources=tuple(sorted({e.source for e in examples})),
        pose_variance_dims=pose.variance_dims, pose_residuals_deg=pose.residuals_deg, robot=robot,
        joints=tuple(legs.joints), root_axes=legs.root_axes, body_geometry=getattr(legs, "body_geometry", None))
