"""The command line as a new user meets it: no silent defaults, errors that show the right usage, a port that
is never ignored, output that can be piped into ``head``, the robot named by its name, dry runs that do not
report timing figures exact by construction, and heel strikes of files that carry none."""

from __future__ import annotations

import subprocess
import sys

import pytest

from helpers import REPO_ROOT, run_cli


@pytest.fixture(scope="module")
def walk_csv(tmp_path_factory):
    from gaitbot.app.cli import main

    path = tmp_path_factory.mktemp("walk") / "walk.csv"
    assert main(["generate", "--distance", "1.0", "-o", str(path)]) == 0
    return path


@pytest.mark.parametrize("command", ["plan", "generate -o x.csv", "walk"])
def test_no_source_of_steps_is_one_line_pointing_to_the_command_help(capsys, command):
    """Bad input is one line (the faults issue): the command's own error and its own --help, not the top
    level's list of commands and not a usage block."""
    with pytest.raises(SystemExit) as exit_info:
        run_cli(capsys, *command.split())
    err = capsys.readouterr().err
    assert exit_info.value.code == 2
    name = command.split()[0]
    assert err.count("\n") == 1
    assert err.startswith(f"gaitbot {name}: error: give --steps, --distance or --terrain")
    assert f"(see gaitbot {name} --help)" in err


def test_the_demo_walk_says_what_it_walks(capsys):
    code, out, err = run_cli(capsys, "walk", "--dry-run")
    assert code == 0
    assert "walking the demo, --distance 0.5" in err
    assert "0.500 m planned" in out


@pytest.mark.parametrize("command", ["walk --distance 0.1", "record --duration 1 --yes -o x.csv", "scan"])
def test_a_port_beside_dry_run_is_refused(capsys, tmp_path, command):
    argv = [*command.replace("x.csv", str(tmp_path / "x.csv")).split(), "--dry-run", "--port", "/dev/ttyUSB7"]
    code, _, err = run_cli(capsys, *argv)
    assert code == 2
    assert "--port /dev/ttyUSB7: a dry run uses the mock bus" in err
    assert not (tmp_path / "x.csv").exists()


def test_output_closed_early_ends_quietly(walk_csv):
    """``gaitbot check --json walk.csv | head -1``: the reader goes away; no traceback, status 141."""
    proc = subprocess.Popen([sys.executable, "-m", "gaitbot", "check", "--json", str(walk_csv)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=REPO_ROOT)
    proc.stdout.close()  # the reader is gone before gaitbot writes a byte
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=60) == 141
    assert "Traceback" not in err and "BrokenPipe" not in err


def test_check_names_the_robot_not_its_config_path(capsys, walk_csv):
    code, out, _ = run_cli(capsys, "check", walk_csv)
    assert code == 0
    assert ".toml" not in out and "site-packages" not in out
    assert out.splitlines()[1].startswith("xl430-biped: 1069 frames")


def test_a_dry_run_reports_no_lateness_figures(capsys):
    """On the simulated clock every frame is on time by construction: lateness and bus time are not reported."""
    code, out, _ = run_cli(capsys, "walk", "--dry-run", "--steps", "0.05")
    assert code == 0
    assert "simulated clock" in out
    assert "ateness" not in out and "late by" not in out and "Bus call" not in out


def test_walking_a_csv_counts_its_heel_strikes(capsys, walk_csv):
    """A CSV carries no heel strikes: they are found from the feet (1 m in 0.1 m steps: 10 steps and the close)."""
    code, out, _ = run_cli(capsys, "walk", "--trajectory", walk_csv, "--dry-run")
    assert code == 0
    assert "11 heel strikes" in out


def test_jargon_in_the_plans_is_explained(capsys):
    from helpers import CONFIG_DIR

    code, out, _ = run_cli(capsys, "plan", "--distance", "0.3")
    assert code == 0 and "RV: walking speed over leg length" in out
    code, out, _ = run_cli(capsys, "plan", "--terrain", CONFIG_DIR / "terrain" / "kerb.toml")
    assert code == 0 and "(mid double support, MDS)" in out
    assert not any(line.startswith("MDS") for line in out.splitlines())


@pytest.mark.parametrize("value", ["-0.05,-0.05", "-0.05", "0.05,-0.05", "-.05, -5e-2"])
def test_a_negative_step_list_is_a_value_not_an_option(capsys, value):
    """argparse takes "-0.05,-0.05" for an option ("expected one argument"); it is a list of steps, refused
    by what it says (one line naming the step), exit 2."""
    code, out, err = run_cli(capsys, "plan", "--steps", value)
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "step lengths must be 0 or more" in err and "expected one argument" not in err


def test_a_negative_velocity_is_a_value(capsys):
    code, out, err = run_cli(capsys, "plan", "--robot", "op3", "--velocity", "-0.02,0,0", "--duration", "3")
    assert code == 0, err
    with pytest.raises(SystemExit) as stop:  # an option is still an option
        run_cli(capsys, "plan", "--steps", "--distance", "1")
    assert stop.value.code == 2 and "expected one argument" in capsys.readouterr().err
