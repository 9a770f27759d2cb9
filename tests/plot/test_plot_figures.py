"""``gaitbot plot``'s pictures read at a glance: legends hide no curve, the clearance trace does not jump where
the ground under a foot changes, heel strikes are visible, the stick figures are few enough to tell apart."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("matplotlib")

from gaitbot.gait.terrain.course_file import load_course  # noqa: E402
from gaitbot.plot.figures import MAX_POSES, ground_profile, sole_clearance, trajectory_figure  # noqa: E402
from gaitbot.app.options import gait_source  # noqa: E402
from gaitbot.app.planned_walk import terrain_walk  # noqa: E402
from helpers import CONFIG_DIR, fk_foot, config  # noqa: E402

KERB = CONFIG_DIR / "terrain" / "kerb.toml"


@pytest.fixture(scope="module")
def kerb():
    from argparse import Namespace

    source = gait_source(Namespace(robot=None, thigh=None, shank=None, foot=None, clearance=None, rate=None))
    walk = terrain_walk(source, str(KERB))
    return source, walk.trajectory, load_course(KERB).terrain


@pytest.fixture(scope="module")
def figure(kerb):
    import matplotlib.pyplot as plt

    source, trajectory, terrain = kerb
    fig = trajectory_figure(trajectory, source.geometry, source.settings.clearance, "kerb", terrain)
    fig.canvas.draw()
    yield fig
    plt.close(fig)


def test_legends_sit_outside_the_curves(figure):
    for ax in figure.axes:
        legend = ax.get_legend()
        assert legend is not None
        box, area = legend.get_window_extent(), ax.get_window_extent()
        assert box.x0 >= area.x1 - 1, "a legend inside the plot hides what is under it"


def test_the_clearance_trace_is_continuous_over_the_kerb_edge(kerb):
    """The distance from each sole to the terrain (treads and risers) moves by less than 5 mm a frame at 60 Hz;
    the lowest point's height above the ground under it jumps by the kerb's 35 mm where the toe crosses its edge."""
    source, trajectory, terrain = kerb
    cfg = config("xl430-biped")
    profile = ground_profile(terrain, -0.5, 2.0)
    jumps = []
    for side in (0, 1):
        _, heel, toe = fk_foot(cfg, trajectory.angles_rad[:, 3 * side:3 * side + 3], trajectory.root_xz_m)
        assert np.abs(np.diff(sole_clearance(heel, toe, profile))).max() < 0.005
        naive = np.minimum(heel[:, 1] - terrain.height_at(heel[:, 0]), toe[:, 1] - terrain.height_at(toe[:, 0]))
        jumps.append(np.abs(np.diff(naive)).max())
    assert max(jumps) > 0.03  # what the trace would show measured the old way


def test_sole_clearance_is_the_distance_to_treads_and_risers():
    profile = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.05], [2.0, 0.05]])
    # above the floor; beside the riser (1 cm from it, 3 cm above the floor); over the kerb's top
    heel, toe = np.array([[0.2, 0.01], [0.9, 0.03], [1.5, 0.07]]), np.array([[0.3, 0.02], [0.99, 0.03], [1.6, 0.08]])
    np.testing.assert_allclose(sole_clearance(heel, toe, profile), [0.01, 0.01, 0.02], atol=1e-12)


def test_heel_strikes_are_drawn_to_be_seen_and_stick_figures_are_few(figure, kerb):
    ax_angles, _, ax_stick = figure.axes[:3]
    strikes = [line for line in ax_angles.get_lines() if line.get_linestyle() == "--" and len(line.get_xdata()) == 2
               and line.get_xdata()[0] == line.get_xdata()[1]]
    assert len(strikes) == len(kerb[1].heel_strikes)
    assert all(line.get_linewidth() >= 1.0 and line.get_alpha() >= 0.7 for line in strikes)
    legs = [line for line in ax_stick.get_lines() if len(line.get_xdata()) == 6]
    assert 2 * 4 <= len(legs) <= 2 * MAX_POSES


def test_the_stick_figure_height_is_z(figure):
    """The files and the world frame call height z (REP-103: x forward, y left, z up)."""
    stick = [ax for ax in figure.axes if ax.get_xlabel().startswith("x (m)")]
    assert len(stick) == 1 and stick[0].get_ylabel() == "z (m)"


def test_a_torso_held_upright_gets_no_empty_panel(tmp_path, monkeypatch):
    """op3's straight walk keeps its torso upright: no panel of three flat lines; a turning walk keeps it."""
    import dataclasses

    from matplotlib.figure import Figure

    from gaitbot.app.planned_walk import balanced_plan
    from gaitbot.app.options import gait_source
    from gaitbot.plot.balance import plot_balance
    from argparse import Namespace

    robot = config("op3")
    source = gait_source(Namespace(robot="op3", thigh=None, shank=None, foot=None, clearance=None, rate=None), robot)
    walk = balanced_plan(source, [0.04, 0.04], None).walk.trajectory()
    seen = []
    monkeypatch.setattr(Figure, "savefig", lambda fig, *a, **k: seen.append([ax.get_ylabel() for ax in fig.axes]))
    plot_balance(walk, robot, tmp_path / "a.png")
    yaw = np.zeros((len(walk), 3))
    yaw[:, 2] = np.radians(np.linspace(0.0, 30.0, len(walk)))
    plot_balance(dataclasses.replace(walk, torso_rpy_rad=yaw), robot, tmp_path / "b.png")
    assert "torso (deg)" not in seen[0] and len(seen[0]) == 2
    assert "torso (deg)" in seen[1] and len(seen[1]) == 3
