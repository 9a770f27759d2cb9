"""Eigen-gaits (seed 004): fit on flat walks at 8 step lengths, synthesise in between, compare with the walker.

Expected values come from the walker (independent of the model) and from the definitions: the
eigen-motions solve eq. 10 and are orthonormal in L2 (checked by quadrature, not by the code's
own algebra), a pose-constrained motion passes through the pose, files with errors exit 2.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from gaitbot.app.cli import main
from gaitbot.gait import generate_walk
from gaitbot.gait.eigen import (FitOptions, cycles_from_trajectory, detect_heel_strikes, fit_model, synthesize_walk,
                                walk_label)
from gaitbot.gait.eigen import ExampleCycle
from gaitbot.gait.eigen.basis import BSplineBasis, FourierBasis, fit_coefficients
from gaitbot.gait.eigen.model import EigenModelError
from gaitbot.gait.eigen.pose import pose_pca
from gaitbot.gait.footfall import swing_clearances
from gaitbot.gait.eigen.synth import root_from_contact
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.walk_settings import leg_geometry, walk_settings
from gaitbot.app.options import load_robot

CFG = load_robot("xl430-biped")
LEG, SETTINGS = leg_geometry(CFG), walk_settings(CFG)
TRAIN = [0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09]
HELD_OUT = [0.025, 0.045, 0.065, 0.085]


def walk(step):
    return generate_walk(LEG, [step] * 6, SETTINGS)


def examples(steps):
    out = []
    for step in steps:
        cycles = cycles_from_trajectory(walk(step), LEG, f"w{step}")
        out += [replace(c, step_length_m=walk_label(cycles)) for c in cycles]
    return out


@pytest.fixture(scope="module")
def library():
    return examples(TRAIN)


@pytest.fixture(scope="module")
def truth():
    return {s: cycles_from_trajectory(walk(s), LEG)[0] for s in HELD_OUT}


def rms_error_deg(model, step, cycle, components=None):
    duration, warp, _ = model.timing_for(step)
    n = len(cycle.angles_rad)
    q = model.poses(model.aligned_phase(np.arange(n) / n, warp), model.coefficients_for(step, components))
    return float(np.degrees(np.sqrt(np.mean((q - cycle.angles_rad) ** 2))))


def test_cycles_are_the_walkers_steady_cycles():
    tr = walk(0.06)
    cycles = cycles_from_trajectory(tr, LEG)
    frames = round(SETTINGS.cycle_s * SETTINGS.rate_hz)
    assert len(cycles) == 2 and all(len(c.angles_rad) == frames for c in cycles)
    assert walk_label(cycles) == pytest.approx(0.06, abs=1e-12)
    assert [c.right_strike_phase for c in cycles] == pytest.approx([0.5, 0.5])
    np.testing.assert_allclose(cycles[0].angles_rad, cycles[1].angles_rad, atol=1e-8)  # periodic: steady part


def test_heel_strikes_detected_from_contact_match_the_planned_ones():
    tr = walk(0.07)
    found = detect_heel_strikes(Trajectory(tr.t_s, tr.angles_rad, tr.root_m), LEG)
    planned = tr.heel_strikes
    assert [h.leg for h in found[:len(planned)]] == [h.leg for h in planned]
    assert [h.t_s for h in found[:len(planned)]] == pytest.approx([h.t_s for h in planned], abs=1.5 / SETTINGS.rate_hz)
    assert [h.x_m for h in found[:len(planned)]] == pytest.approx([h.x_m for h in planned], abs=2e-3)


@pytest.mark.parametrize("basis", [FourierBasis(11), BSplineBasis(12)])
def test_gram_and_penalty_are_the_integrals(basis):
    s = (np.arange(20000) + 0.5) / 20000  # midpoint rule, independent of the quadrature in the code
    phi, d2 = basis.evaluate(s), basis.evaluate(s, derivative=2)
    np.testing.assert_allclose(basis.gram(), phi.T @ phi / len(s), atol=1e-6)
    np.testing.assert_allclose(basis.penalty(), d2.T @ d2 / len(s), rtol=1e-3, atol=1e-2)


# ---- roughness penalty --------------------------------------------------------------------------

def noisy_cycle(n=100, seed=1):
    s = np.arange(n) / n
    clean = 0.4 * np.sin(2 * np.pi * s) + 0.1 * np.cos(6 * np.pi * s)
    return s, clean + np.random.default_rng(seed).normal(0.0, 0.02, n)


def test_zero_roughness_is_plain_least_squares():
    s, x = noisy_cycle()
    for basis in (FourierBasis(21), BSplineBasis(15)):
        plain = np.linalg.lstsq(basis.evaluate(s), x, rcond=None)[0]
        np.testing.assert_allclose(fit_coefficients(basis, s, x, 0.0), plain, atol=1e-10)


def test_fourier_roughness_shrinks_each_harmonic_by_the_closed_form():
    """On n equally spaced samples the Fourier columns are orthogonal with squared norm n, and the penalty
    matrix is diagonal (2 pi k)^4, so each coefficient is the plain one divided by 1 + lam (2 pi k)^4 / n."""
    s, x = noisy_cycle()
    basis, lam = FourierBasis(21), 1e-6
    plain = fit_coefficients(basis, s, x, 0.0)
    k = np.concatenate([[0], np.repeat(np.arange(1, 11), 2)])
    np.testing.assert_allclose(fit_coefficients(basis, s, x, lam), plain / (1 + lam * (2 * np.pi * k) ** 4 / len(s)),
                               atol=1e-12)


def test_bspline_roughness_matches_an_augmented_least_squares_with_numerical_second_derivatives():
    s, x = noisy_cycle()
    basis, lam = BSplineBasis(20), 1e-5
    # independent: R from finite differences of the basis on a fine midpoint grid, then the penalised
    # problem as one stacked least-squares system [Phi; sqrt(lam) R^(1/2)] c = [x; 0]
    h = 1e-5  # smaller than the grid's distance to either end
    grid = (np.arange(20000) + 0.5) / 20000
    d2 = (basis.evaluate(grid + h) - 2 * basis.evaluate(grid) + basis.evaluate(grid - h)) / h**2
    r_num = d2.T @ d2 / len(grid)
    w, v = np.linalg.eigh(r_num)
    root = (v * np.sqrt(np.clip(w, 0, None))).T
    stacked = np.vstack([basis.evaluate(s), np.sqrt(lam) * root])
    want = np.linalg.lstsq(stacked, np.concatenate([x, np.zeros(len(root))]), rcond=None)[0]
    got = fit_coefficients(basis, s, x, lam)
    assert np.abs(basis.evaluate(s) @ (got - want)).max() < 1e-6 * np.abs(x).max()  # the penalty moves it ~1e-2


@pytest.mark.parametrize("basis", [FourierBasis(31), BSplineBasis(30)])
def test_a_larger_roughness_penalty_gives_a_smoother_fit_further_from_the_data(basis):
    s, x = noisy_cycle()
    fine = (np.arange(5000) + 0.5) / 5000
    roughness, misfit = [], []
    for lam in (0.0, 1e-8, 1e-7, 1e-6, 1e-5):
        c = fit_coefficients(basis, s, x, lam)
        roughness.append(np.mean((basis.evaluate(fine, derivative=2) @ c) ** 2))  # int x''^2 by the midpoint rule
        misfit.append(np.sum((basis.evaluate(s) @ c - x) ** 2))
    assert np.all(np.diff(roughness) < 0) and np.all(np.diff(misfit) > 0)
    assert roughness[-1] < 0.5 * roughness[0]  # most of the noise's bending gone


def test_a_model_fitted_with_a_roughness_penalty_has_a_smoother_mean_cycle(library):
    plain, smooth = fit_model(library, LEG, 60.0), fit_model(library, LEG, 60.0, FitOptions(roughness=1e-6))
    fine = (np.arange(2000) + 0.5) / 2000

    def bending(model):
        return np.mean((model.basis.evaluate(fine, derivative=2) @ model.coef_mean.T) ** 2)

    assert smooth.roughness == 1e-6 and bending(smooth) < bending(plain)


# ---- B-spline basis: non-periodic motion ----------------------------------------------------------

def start_segment(step):
    """The walker from standing to its second heel strike: a motion that does not repeat."""
    tr = walk(step)
    k = int(np.argmin(np.abs(tr.t_s - tr.heel_strikes[1].t_s)))
    return tr.angles_rad[:k + 1], float(tr.t_s[k])


def test_bspline_knots_are_clamped_cubic_and_the_basis_sums_to_one():
    basis = BSplineBasis(12)
    assert len(basis.knots) == basis.n_basis + 4
    np.testing.assert_array_equal(basis.knots[:4], 0.0)
    np.testing.assert_array_equal(basis.knots[-4:], 1.0)
    np.testing.assert_allclose(np.diff(basis.knots[3:-3]), 1.0 / (basis.n_basis - 3))
    s = np.linspace(0.0, 1.0, 1001)  # both ends included: a non-periodic fit samples s = 1
    values = basis.evaluate(s)
    np.testing.assert_allclose(values.sum(axis=1), 1.0, atol=1e-12)
    assert values.min() >= -1e-15
    np.testing.assert_allclose(values[0], np.eye(12)[0], atol=1e-12)  # clamped: the ends are the end coefficients
    np.testing.assert_allclose(values[-1], np.eye(12)[-1], atol=1e-12)


def test_bspline_gram_matches_adaptive_quadrature():
    from scipy.integrate import quad

    basis = BSplineBasis(9)
    gram = basis.gram()
    for i, j in ((0, 0), (0, 1), (3, 5), (4, 4), (8, 8), (7, 8)):
        value, _ = quad(lambda x: basis.evaluate([x])[0, i] * basis.evaluate([x])[0, j], 0.0, 1.0,
                        points=list(basis.knots[4:-4]), epsabs=1e-13)
        assert gram[i, j] == pytest.approx(value, abs=1e-10)


def test_bspline_fits_a_start_from_standing_that_a_fourier_basis_cannot():
    """199 frames from standing through the first step, fitted by least squares: RMS under 0.15 deg and
    both end poses within 0.1 deg with 40 B-splines; 41 Fourier functions must join the end to the start."""
    q, _ = start_segment(0.06)
    s = np.linspace(0.0, 1.0, len(q))
    bspline = BSplineBasis(40)
    err = np.degrees(bspline.evaluate(s) @ fit_coefficients(bspline, s, q) - q)
    assert np.sqrt(np.mean(err**2)) < 0.15
    assert np.abs(err[[0, -1]]).max() < 0.1
    fourier = FourierBasis(41)
    err_f = np.degrees(fourier.evaluate(s) @ fit_coefficients(fourier, s, q) - q)
    assert np.abs(err_f[[0, -1]]).max() > 1.0


@pytest.mark.slow
def test_a_non_periodic_model_learns_starts_at_eight_step_lengths_and_synthesises_those_between():
    """Starts from standing at the 8 training step lengths, B-spline fPCA (periodic=False): the start at a
    held-out step length within 0.6 deg RMS of the walker's own, beginning at the standing pose."""
    examples = []
    for step in TRAIN:
        q, duration = start_segment(step)
        examples.append(ExampleCycle(q, duration, 0.5, step, f"start {step}"))
    model = fit_model(examples, LEG, 60.0, FitOptions(basis="bspline", n_basis=30), periodic=False)
    assert not model.periodic and model.basis_kind == "bspline"
    for step in HELD_OUT:
        q, duration = start_segment(step)
        _, warp, _ = model.timing_for(step)
        s = model.aligned_phase(np.linspace(0.0, 1.0, len(q)), warp)
        synth = model.poses(s, model.coefficients_for(step))
        assert np.degrees(np.sqrt(np.mean((synth - q) ** 2))) < 0.6
        assert np.degrees(np.abs(synth[0])).max() < 0.1  # starts standing


def test_eigen_motions_solve_eq10_and_are_orthonormal(library):
    model = fit_model(library, LEG, 60.0)
    s = (np.arange(4000) + 0.5) / 4000
    phi = model.basis.evaluate(s)
    xi = np.stack([phi @ b.T for b in model.eigen_coefs])  # (M, n, d) in the reduced pose space
    gram = np.einsum("ind,jnd->ij", xi, xi) / len(s)
    np.testing.assert_allclose(gram, np.eye(len(xi)), atol=1e-6)
    # eq. 10: N^-1 C^T C W b = lambda b, C the centred coefficients of the examples, recomputed here by least squares
    d, K = model.coef_mean.shape
    assert model.scores.shape[0] == len(library)
    centred = (model.scores @ model.eigen_coefs.reshape(len(xi), -1))  # examples rebuilt from all eigen-motions
    W = np.kron(np.eye(d), model.basis.gram())
    lhs = centred.T @ centred @ W @ model.eigen_coefs.reshape(len(xi), -1).T / len(library)
    np.testing.assert_allclose(lhs, model.eigen_coefs.reshape(len(xi), -1).T * model.eigenvalues, atol=1e-8)


def steady_step_lengths(trajectory):
    xs = [h.x_m for h in trajectory.heel_strikes]
    return np.diff(xs)[2:-2]  # leave out the walker's start and stop steps and the joins


def synthesised_swing_clearances_m(trajectory):
    """Least swing-sole height (20-80% of each swing) of every swing ending inside the synthesised cycles."""
    inside = {h.t_s for h in trajectory.heel_strikes[2:-1]}
    return [c for h, c in swing_clearances(LEG, trajectory) if h.t_s in inside]


def test_held_out_step_lengths_match_the_walker(library, truth, capsys):
    """Fit on 8 step lengths, synthesise 4 in between from the label regression, compare with the walker.

    The measured figures are docs/eigen-gaits.md's (printed by tools/bench_eigen.py, compared with a fresh
    run by tests/docs/test_figures.py); the bounds here are what the default pose rule must keep."""
    default = fit_model(library, LEG, 60.0)
    paper = fit_model(library, LEG, 60.0, FitOptions(pose_tolerance_deg=float("inf")))
    assert default.n_components == 2 and paper.n_components == 2  # 95% (eq. 11) with two eigen-motions
    assert default.variance_explained[:2].sum() > 0.95
    assert paper.pose_dims == 3 and default.pose_dims == 6
    lines = []
    for step, cycle in truth.items():
        e_default, e_paper = rms_error_deg(default, step, cycle), rms_error_deg(paper, step, cycle)
        walk = synthesize_walk(default, SETTINGS, step, cycles=3)
        steps = steady_step_lengths(walk)
        step_error = float(np.abs(steps - step).max() / step)
        clearance = min(synthesised_swing_clearances_m(walk))
        lines.append(f"step {step}: RMS {e_default:.2f} deg, steps within {100 * step_error:.1f}%, clearance "
                     f"{1000 * clearance:.1f} mm (6 pose axes, 2 eigen-motions); RMS {e_paper:.2f} deg with the "
                     f"95% pose rule alone (3 axes)")
        assert e_default < 0.4
        assert step_error < 0.03
        assert clearance >= SETTINGS.clearance  # the synthesised swings keep the walker's clearance rule
        assert e_paper < 3.5  # what the 5% the paper's rule drops costs on six joints
    with capsys.disabled():
        print("\n" + "\n".join(lines))


def test_the_pose_rule_adds_axes_until_the_examples_move_less_than_the_tolerance():
    rng = np.random.default_rng(7)
    scores = rng.normal(size=(2000, 4)) * np.radians([30.0, 15.0, 8.0, 2.0])
    axes = np.linalg.qr(rng.normal(size=(6, 6)))[0][:, :4]
    poses = scores @ axes.T + 0.1  # rank 4: two axes carry nothing
    for variance, tolerance, want in ((0.95, float("inf"), 3), (0.95, 0.5, 4), (0.999, float("inf"), 4)):
        pca = pose_pca(poses, variance, tolerance)
        assert pca.dims == want
        # the projection error, recomputed by least squares on the kept axes
        fit = np.linalg.lstsq(pca.axes, (poses - pca.mean).T, rcond=None)[0]
        worst = np.degrees(np.abs(poses - pca.mean - (pca.axes @ fit).T).max())
        assert pca.residuals_deg[want - 1] == pytest.approx(worst, abs=1e-9)
        assert worst <= tolerance
    assert pose_pca(poses, 0.95, 0.5).variance_dims == 3


def test_synthesised_walk_step_length_and_no_sliding(library):
    model = fit_model(library, LEG, 60.0, FitOptions(pose_variance=1.0))
    for step in (0.045, 0.065):
        tr = synthesize_walk(model, SETTINGS, step, cycles=3)
        steps = steady_step_lengths(tr)
        assert np.all(np.abs(steps - step) < 0.05 * step), steps  # within 5% of the request
        # the stance foot's contact point does not move while it supports
        root, stance = root_from_contact(LEG, tr.angles_rad, tr.root_m[0])
        np.testing.assert_allclose(root, tr.root_xz_m, atol=1e-12)
        assert np.all(np.diff(tr.root_m[:, 0]) > -2e-3)  # the body does not run backwards
        speed = np.degrees(np.abs(np.diff(tr.angles_rad, axis=0))).max() * SETTINGS.rate_hz
        assert speed < 300.0  # the robot's velocity limit; continuity at the joins


def test_pose_constraint_passes_through_the_pose(library, truth):
    model = fit_model(library, LEG, 60.0, FitOptions(pose_variance=1.0))
    cycle = truth[0.065]
    n = len(cycle.angles_rad)
    for k in (n // 5, n // 2 + 7):
        pose = cycle.angles_rad[k]  # a pose the walker takes at 0.065 m, asked of a 0.045 m cycle
        duration, warp, _ = model.timing_for(0.045)
        s = float(model.aligned_phase(k / n, warp))
        alpha, miss = model.through_pose(pose, s, model.coefficients_for(0.045, len(model.eigenvalues)))
        assert np.degrees(np.abs(miss)).max() < 0.1
        got = model.poses([s], alpha)[0]
        assert np.degrees(np.abs(got - pose)).max() < 0.1
        before = model.poses([s], model.coefficients_for(0.045))[0]
        assert np.degrees(np.abs(before - pose)).max() > 1.0  # the constraint changed something


def test_too_few_examples_for_the_components(library):
    with pytest.raises(EigenModelError, match="at most"):
        fit_model(library[:4], LEG, 60.0, FitOptions(components=4))


# ---- command line ------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("eigen")
    paths = []
    for step in TRAIN:
        p = d / f"walk_{step}.npz"
        walk(step).save(p)
        paths.append(str(p))
    return d, paths


def test_cli_fit_synth_check_plot(files, capsys):
    d, paths = files
    model = str(d / "model.npz")
    assert main(["eigen", "fit", *paths, "-o", model]) == 0
    out = capsys.readouterr().out
    assert "2 eigen-motions kept" in out and "6 of 6 axes kept" in out and "95% of the variance needs only 3" in out
    tables = {}
    for line in out.splitlines():
        fields = line.split()
        if "variance %" in line:  # a table header: "pose axis  variance %  cumulative %"
            current = tables.setdefault(line.split("variance")[0].split()[-1], [])
        elif len(fields) in (3, 4) and fields[0].isdigit():
            current.append((float(fields[1]), float(fields[2]), fields[-1] == "kept"))
    for rows in tables.values():  # variance per component printed; it adds up, the kept ones reach 95%
        assert sum(r[0] for r in rows) == pytest.approx(100.0, abs=0.01)
        assert max(r[1] for r in rows if r[2]) >= 95.0
    assert len(tables["axis"]) == 6 and sum(r[2] for r in tables["eigen-motion"]) == 2
    csv = str(d / "walk.csv")
    assert main(["eigen", "synth", model, "--step-length", "0.065", "--cycles", "2", "-o", csv]) == 0
    capsys.readouterr()
    assert main(["check", csv, "--robot", "xl430-biped"]) == 0
    capsys.readouterr()
    assert main(["walk", "--dry-run", "--trajectory", csv]) == 0  # an ordinary trajectory: the robot walks it
    assert "Walk completed" in capsys.readouterr().out
    png = d / "eig.png"
    assert main(["plot", model, "-o", str(png)]) == 0
    assert png.stat().st_size > 20000
    walk_csv = Trajectory.load(csv)
    assert walk_csv.angles_deg[0] == pytest.approx(np.zeros(6), abs=1e-6)  # starts standing
    assert walk_csv.angles_deg[-1] == pytest.approx(np.zeros(6), abs=1e-6)  # ends standing


@pytest.mark.slow
def test_cli_pose_constraint(files, capsys):
    """The pose a 0.065 m walk takes 0.567 s after a left heel strike, forced on a 0.05 m walk at that time."""
    d, paths = files
    model = str(d / "model_default.npz")
    assert main(["eigen", "fit", *paths, "-o", model]) == 0
    out_npz = str(d / "posed.npz")
    source = walk(0.065)
    k = int(np.argmin(np.abs(source.t_s - (source.heel_strikes[3].t_s + 0.567))))
    pose = np.degrees(source.angles_rad[k])
    arg = ",".join(f"{v:.6f}" for v in pose)
    assert main(["eigen", "synth", model, "--step-length", "0.05", "--components", "7", "--pose-deg", arg,
                 "--pose-time", "0.567", "-o", out_npz]) == 0
    tr = Trajectory.load(out_npz)
    lefts = [h.t_s for h in tr.heel_strikes if h.leg == "left"]
    for start in lefts[:3]:  # every synthesised cycle passes through the pose at its requested time
        k = int(np.argmin(np.abs(tr.t_s - (start + 0.567))))
        assert abs(tr.t_s[k] - (start + 0.567)) < 0.5 / SETTINGS.rate_hz
        assert np.abs(tr.angles_deg[k] - pose).max() < 0.1
    assert np.abs(steady_step_lengths(tr) - 0.065).max() < 0.005  # the pose brings its step length along


@pytest.mark.slow
def test_cli_a_forced_pose_that_distorts_the_walk_is_written_but_flagged(files, tmp_path, capsys):
    d, paths = files
    model = str(tmp_path / "m.npz")
    assert main(["eigen", "fit", *paths, "-o", model]) == 0
    pose = np.degrees(walk(0.065).angles_rad[400])  # a mid-swing pose asked for at the wrong moment
    out = tmp_path / "bent.csv"
    assert main(["eigen", "synth", model, "--step-length", "0.05", "--components", "7", "--pose-deg",
                 ",".join(f"{v:.6f}" for v in pose), "--pose-time", "1.0", "-o", str(out)]) == 1
    assert "gaitbot walk would refuse it" in capsys.readouterr().err
    assert main(["check", str(out)]) == 1


def test_cli_errors_exit_2(files, tmp_path, capsys):
    d, paths = files
    bad = tmp_path / "bad.csv"
    bad.write_text("t_s,nonsense\n1,2\n")
    assert main(["eigen", "fit", str(bad), paths[0], "-o", str(tmp_path / "m.npz")]) == 2
    assert "bad.csv" in capsys.readouterr().err
    assert main(["eigen", "fit", paths[0], paths[1], "--components", "5", "-o", str(tmp_path / "m.npz")]) == 2
    err = capsys.readouterr().err
    assert "at most" in err and len(err.strip().splitlines()) == 1
    model = str(tmp_path / "m.npz")
    assert main(["eigen", "fit", *paths, "-o", model]) == 0
    capsys.readouterr()
    outside = "0,0,0,0,150,0"  # right knee past its 110 deg limit
    assert main(["eigen", "synth", model, "--step-length", "0.05", "--pose-deg", outside, "--pose-time", "1",
                 "-o", str(tmp_path / "w.csv")]) == 2
    err = capsys.readouterr().err
    assert "knee_pitch_right" in err and "limits" in err and len(err.strip().splitlines()) == 1
    assert main(["eigen", "synth", model, "--step-length", "0.15", "-o", str(tmp_path / "w.csv")]) == 2
    assert main(["eigen", "synth", paths[0], "--step-length", "0.05", "-o", str(tmp_path / "w.csv")]) == 2
    assert "not an eigen-gait model" in capsys.readouterr().err


def one_line_error(capsys, *words):
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    for word in words:
        assert word in err, err


def test_cli_malformed_and_unusable_examples_exit_2(files, tmp_path, capsys):
    d, paths = files
    model = str(tmp_path / "m.npz")
    standing = tmp_path / "standing.csv"
    tr = walk(0.05)
    Trajectory.sagittal(tr.t_s[:200], np.zeros((200, 6)), np.tile([0.0, 0.25], (200, 1))).save(standing)
    assert main(["eigen", "fit", str(standing), paths[0], "-o", model]) == 2
    one_line_error(capsys, "standing.csv", "no complete steady cycle")
    truncated = tmp_path / "cut.npz"
    truncated.write_bytes(open(paths[0], "rb").read()[:300])
    assert main(["eigen", "fit", str(truncated), paths[1], "-o", model]) == 2
    one_line_error(capsys, "cut.npz")
    nan = tmp_path / "nan.csv"
    walk(0.05).save(nan)
    lines = nan.read_text().splitlines()
    lines[50] = ",".join(["nan"] + lines[50].split(",")[1:])
    nan.write_text("\n".join(lines) + "\n")
    assert main(["eigen", "fit", str(nan), paths[1], "-o", model]) == 2
    one_line_error(capsys, "nan.csv", "not a finite number")
    slow = tmp_path / "slow.npz"
    Trajectory(tr.t_s * 2, tr.angles_rad, tr.root_m, tuple(replace(h, t_s=2 * h.t_s) for h in tr.heel_strikes)).save(slow)
    assert main(["eigen", "fit", str(slow), paths[1], "-o", model]) == 2
    one_line_error(capsys, "different frame rates")
    assert main(["eigen", "fit", paths[0], paths[0], "-o", model]) == 2
    one_line_error(capsys, "distinct step length")
    assert main(["eigen", "fit", *paths, "-o", str(tmp_path / "m.txt")]) == 2
    one_line_error(capsys, ".npz")


def test_cli_synth_bad_requests_exit_2(files, tmp_path, capsys):
    d, paths = files
    model = str(tmp_path / "m.npz")
    assert main(["eigen", "fit", *paths[:3], "-o", model]) == 0
    capsys.readouterr()
    out = str(tmp_path / "w.csv")
    assert main(["eigen", "synth", model, "--step-length", "0.03", "--components", "9", "-o", out]) == 2
    one_line_error(capsys, "--components 9")
    assert main(["eigen", "synth", model, "--step-length", "0.03", "--pose-deg", "1,2,3", "--pose-time", "1",
                 "-o", out]) == 2
    one_line_error(capsys, "--pose-deg", "6 angles")
    assert main(["eigen", "synth", model, "--step-length", "0.03", "--pose-deg", "0,0,0,0,0,0", "-o", out]) == 2
    one_line_error(capsys, "--pose-time")
    assert main(["eigen", "synth", model, "--step-length", "0.03", "--pose-deg", "0,0,0,0,0,0", "--pose-time", "99",
                 "-o", out]) == 2
    one_line_error(capsys, "--pose-time")
    assert main(["eigen", "synth", model, "--step-length", "0.03", "--pose-deg=-50,0,0,0,0,0", "--pose-time", "1",
                 "-o", out]) == 2  # left hip below its -45 deg limit
    one_line_error(capsys, "hip_pitch_left", "limits")
    assert not (tmp_path / "w.csv").exists()


def test_walk_refuses_a_trajectory_file_not_sampled_evenly(tmp_path, capsys):
    tr = walk(0.05)
    t = tr.t_s.copy()
    t[100:] += 0.004  # one sample late by a quarter of a frame
    path = tmp_path / "uneven.csv"
    Trajectory(t, tr.angles_rad, tr.root_m).save(path)
    assert main(["walk", "--dry-run", "--trajectory", str(path)]) == 2
    one_line_error(capsys, "uneven.csv", "not evenly spaced")


def test_plot_finds_the_heel_strikes_eigen_fit_finds(tmp_path):
    """A CSV carries no heel strikes: plot and eigen fit detect them with the same rule (footfall.py)."""
    from gaitbot.plot.figures import _detected_heel_strikes, _foot_lows

    tr = walk(0.06)
    csv = tmp_path / "w.csv"
    tr.save(csv)
    loaded = Trajectory.load(csv)
    for found in (_detected_heel_strikes(LEG, loaded, _foot_lows(LEG, loaded)), detect_heel_strikes(loaded, LEG)):
        assert [h.leg for h in found] == [h.leg for h in tr.heel_strikes]
        assert [h.t_s for h in found] == pytest.approx([h.t_s for h in tr.heel_strikes], abs=1.5 / SETTINGS.rate_hz)
        assert [h.x_m for h in found] == pytest.approx([h.x_m for h in tr.heel_strikes], abs=2e-3)


def test_fit_learns_from_an_example_beyond_the_limits_with_a_warning(files, tmp_path, capsys):
    """A recording a hand took past a limit is an example like any other, but fit says so."""
    d, paths = files
    tr = walk(0.05)
    angles = tr.angles_rad.copy()
    angles[-20:, 1] = np.radians(115.0)  # the left knee held past its 110 deg limit after the walk
    beyond = tmp_path / "beyond.npz"
    Trajectory(tr.t_s, angles, tr.root_m, tr.heel_strikes).save(beyond)
    assert main(["eigen", "fit", str(beyond), *paths[:3], "-o", str(tmp_path / "m.npz")]) == 0
    captured = capsys.readouterr()
    assert "beyond.npz" in captured.err and "knee_pitch_left" in captured.err and "warning" in captured.err
    assert "wrote" in captured.out
