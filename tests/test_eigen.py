"""Eigen-gaits (seed 004): fit on flat walks at 8 step lengths, synthesise in between, compare with the walker.

Expected values come from the walker (independent of the model) and from the definitions: the
eigen-motions solve eq. 10 and are orthonormal in L2 (checked by quadrature, not by the code's
own algebra), a pose-constrained motion passes through the pose, files with errors exit 2.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from gaitbot.cli import main
from gaitbot.gait import generate_walk
from gaitbot.gait.eigen import (FitOptions, cycles_from_trajectory, detect_heel_strikes, fit_model, synthesize_walk,
                                walk_label)
from gaitbot.gait.eigen.basis import BSplineBasis, FourierBasis
from gaitbot.gait.eigen.model import EigenModelError
from gaitbot.gait.eigen.synth import root_from_contact
from gaitbot.gait.trajectory import Trajectory
from gaitbot.robot.gait_setup import leg_geometry, walk_settings
from gaitbot.session import load_robot

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


def test_held_out_step_lengths_match_the_walker(library, truth, capsys):
    """Fit on 8 step lengths, synthesise 4 in between from the label regression, compare with the walker."""
    default = fit_model(library, LEG, 60.0)
    full_pose = fit_model(library, LEG, 60.0, FitOptions(pose_variance=1.0))
    assert default.n_components == 2 and full_pose.n_components == 2  # 95% (eq. 11) with two eigen-motions
    assert default.pose_dims == 3 and full_pose.pose_dims == 6
    lines = []
    for step, cycle in truth.items():
        e_default, e_full = rms_error_deg(default, step, cycle), rms_error_deg(full_pose, step, cycle)
        lines.append(f"step {step}: RMS {e_default:.2f} deg (pose PCA 95%, 3 axes), {e_full:.2f} deg (all 6 axes); "
                     f"2 eigen-motions")
        # pose PCA at 95% drops 3.7% of the pose variance: a few degrees; with every axis kept, a fraction of one
        assert e_default < 3.5
        assert e_full < 0.4
    with capsys.disabled():
        print("\n" + "\n".join(lines))


def steady_step_lengths(trajectory):
    xs = [h.x_m for h in trajectory.heel_strikes]
    return np.diff(xs)[2:-2]  # leave out the walker's start and stop steps and the joins


def test_synthesised_walk_step_length_and_no_sliding(library):
    model = fit_model(library, LEG, 60.0, FitOptions(pose_variance=1.0))
    for step in (0.045, 0.065):
        tr = synthesize_walk(model, SETTINGS, step, cycles=3)
        steps = steady_step_lengths(tr)
        assert np.all(np.abs(steps - step) < 0.05 * step), steps  # within 5% of the request
        # the stance foot's contact point does not move while it supports
        root, stance = root_from_contact(LEG, tr.angles_rad, tr.root_m[0])
        np.testing.assert_allclose(root, tr.root_m, atol=1e-12)
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
    assert "2 eigen-motions kept" in out and "85." in out
    csv = str(d / "walk.csv")
    assert main(["eigen", "synth", model, "--step-length", "0.065", "--cycles", "2", "-o", csv]) == 0
    capsys.readouterr()
    assert main(["check", csv, "--robot", "xl430-biped"]) == 0
    png = d / "eig.png"
    assert main(["plot", model, "-o", str(png)]) == 0
    assert png.stat().st_size > 20000
    walk_csv = Trajectory.load(csv)
    assert walk_csv.angles_deg[0] == pytest.approx(np.zeros(6), abs=1e-6)  # starts standing
    assert walk_csv.angles_deg[-1] == pytest.approx(np.zeros(6), abs=1e-6)  # ends standing


def test_cli_pose_constraint(files, capsys):
    d, paths = files
    model = str(d / "model_full.npz")
    assert main(["eigen", "fit", *paths, "--pose-variance", "1", "-o", model]) == 0
    out_npz = str(d / "posed.npz")
    pose = np.degrees(walk(0.065).angles_rad[400])
    arg = ",".join(f"{v:.6f}" for v in pose)
    assert main(["eigen", "synth", model, "--step-length", "0.05", "--components", "7", "--pose-deg", arg,
                 "--pose-time", "1.0", "-o", out_npz]) == 0
    tr = Trajectory.load(out_npz)
    lefts = [h.t_s for h in tr.heel_strikes if h.leg == "left"]
    k = int(np.argmin(np.abs(tr.t_s - (lefts[1] + 1.0))))  # the middle cycle, away from the joins
    assert np.abs(tr.angles_deg[k] - pose).max() < 0.1


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
