"""``gaitbot eigen fit/synth`` and the leg: a model remembers the leg it learnt and the robot it is for, and
synthesis for another is refused in one line; the synthesised walk's steps are listed without the closing one."""

from __future__ import annotations

import re

import numpy as np
import pytest

from gaitbot.gait.eigen import EigenGaitModel
from gaitbot.app.cli import main
from helpers import run_cli


def _fit(folder, *leg):
    """A model fitted on two walks (0.03 and 0.07 m steps) generated with ``leg`` options, fitted with them too."""
    paths = []
    for step in (0.03, 0.07):
        path = folder / f"ex_{step}{''.join(leg)}.npz"
        assert main(["generate", "--steps", ",".join([str(step)] * 6), *leg, "-o", str(path)]) == 0
        paths.append(str(path))
    model = folder / f"model{''.join(leg)}.npz"
    assert main(["eigen", "fit", *paths, *leg, "-o", str(model)]) == 0
    return model


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    """A model of the default robot's walks, and one of walks with a 0.10 m thigh (--thigh on generate and fit)."""
    folder = tmp_path_factory.mktemp("eigen")
    return _fit(folder), _fit(folder, "--thigh", "0.1")


def test_the_model_remembers_its_robot_and_leg(models):
    robot, short = (EigenGaitModel.load(p) for p in models)
    assert robot.robot == short.robot == "xl430-biped"
    assert (robot.geometry.thigh, robot.geometry.shank, robot.geometry.foot) == (0.11, 0.11, 0.12)
    assert (short.geometry.thigh, short.geometry.shank, short.geometry.foot) == (0.1, 0.11, 0.12)


def test_synthesis_for_another_robot_is_refused_in_one_line(capsys, models, tmp_path):
    code, out, err = run_cli(capsys, "eigen", "synth", models[0], "--robot", "sts3215-biped", "--step-length", "0.05",
                             "-o", tmp_path / "w.csv")
    assert code == 2 and out == ""
    assert err.count("\n") == 1
    assert "was fitted for xl430-biped, not sts3215-biped" in err
    assert not (tmp_path / "w.csv").exists()


@pytest.mark.parametrize("which, leg", [(0, ("--thigh", "0.1")), (1, ())], ids=["model of the robot's leg",
                                                                               "model of a shorter thigh"])
def test_synthesis_for_another_leg_is_refused_in_one_line(capsys, models, tmp_path, which, leg):
    code, _, err = run_cli(capsys, "eigen", "synth", models[which], *leg, "--step-length", "0.05",
                           "-o", tmp_path / "w.csv")
    assert code == 2
    assert err.count("\n") == 1 and "learnt a leg" in err
    assert not (tmp_path / "w.csv").exists()


def test_synthesis_with_the_model_leg_works_and_lists_no_closing_step(capsys, models, tmp_path):
    code, out, _ = run_cli(capsys, "eigen", "synth", models[1], "--thigh", "0.1", "--step-length", "0.05",
                           "--cycles", "2", "-o", tmp_path / "w.csv")
    assert code == 0
    strikes = int(re.search(r"(\d+) heel strikes", out).group(1))
    listed = [float(v) for v in re.search(r"step lengths between heel strikes ([-\d., ]+) m", out).group(1).split(",")]
    assert len(listed) == strikes - 2  # the gaps between strikes, less the closing step's
    assert min(listed) > 0.04 and np.all(np.asarray(listed) < 0.06)
    assert "closes beside" in out
