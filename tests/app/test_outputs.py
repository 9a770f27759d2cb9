"""Issue 26 items 6 and 7: no command overwrites its own input or a robot config, an output naming a FIFO is
refused at once, and a whole-file output is renamed into place (a failed write leaves the old file)."""

from __future__ import annotations

import os
import shutil

import pytest

from gaitbot.app.options import UsageError
from gaitbot.app.outputs import output_path, write_output
from helpers import CONFIG_DIR, REPO_ROOT, gaitbot


def refused(proc, *words: str) -> None:
    err = proc.stderr.strip()
    assert proc.returncode == 2, proc.stderr + proc.stdout
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    for word in words:
        assert word in err, err


@pytest.fixture(scope="module")
def walk_csv(tmp_path_factory):
    path = tmp_path_factory.mktemp("walk") / "w.csv"
    assert gaitbot("generate", "--steps", "0.05,0.05", "-o", str(path)).returncode == 0
    return path


def test_walk_does_not_record_over_the_trajectory_it_plays(walk_csv, tmp_path):
    before = walk_csv.read_bytes()
    refused(gaitbot("walk", "--dry-run", "--trajectory", str(walk_csv), "--record", str(walk_csv)),
            "--record", "inputs")
    link = tmp_path / "link.csv"
    link.symlink_to(walk_csv)  # the same file after resolving links
    refused(gaitbot("walk", "--dry-run", "--trajectory", str(walk_csv), "--record", str(link)), "--record")
    assert walk_csv.read_bytes() == before


@pytest.mark.slow
def test_eigen_fit_does_not_write_its_model_over_an_example(walk_csv, tmp_path):
    example = tmp_path / "ex.npz"
    assert gaitbot("generate", "--steps", "0.05,0.05,0.05,0.05", "-o", str(example)).returncode == 0
    before = example.read_bytes()
    refused(gaitbot("eigen", "fit", str(example), str(walk_csv), "-o", str(example)), "-o", "inputs")
    assert example.read_bytes() == before


def test_no_command_writes_over_a_robot_config(tmp_path):
    copy = tmp_path / "mine.toml"
    shutil.copyfile(CONFIG_DIR / "op3.toml", copy)
    before = (CONFIG_DIR / "op3.toml").read_bytes()
    refused(gaitbot("calibrate", "--robot", "op3", "-o", "config/op3.toml", "--port", "/dev/null"), "-o")
    refused(gaitbot("calibrate", "--robot", "xl430-biped", "-o", str(copy), "--port", "/dev/null"),
            "robot config")
    assert (CONFIG_DIR / "op3.toml").read_bytes() == before


@pytest.mark.parametrize("argv", [["generate", "--distance", "0.1", "-o", "{fifo}.csv"],
                                  ["walk", "--dry-run", "--distance", "0.1", "--record", "{fifo}.jsonl"]])
def test_an_output_naming_a_fifo_is_refused_without_blocking(argv, tmp_path):
    fifo = tmp_path / "pipe"
    for suffix in (".csv", ".jsonl"):
        os.mkfifo(f"{fifo}{suffix}")
    refused(gaitbot(*[a.format(fifo=fifo) for a in argv], timeout=30), "not a regular file")


def test_output_path_names_the_input_it_would_overwrite(tmp_path):
    source = tmp_path / "in.csv"
    source.write_text("x")
    with pytest.raises(UsageError, match=r"^-o .*in\.csv: is one of this command's inputs"):
        output_path(str(tmp_path / "." / "in.csv"), "-o", inputs=[source])
    assert output_path(str(tmp_path / "new.csv"), "-o", inputs=[source]) == tmp_path / "new.csv"


def test_a_failed_write_leaves_the_old_file_and_no_partial_one(tmp_path):
    out = tmp_path / "w.csv"
    out.write_text("the good one\n")

    def half_then_full_disk(path):
        path.write_text("half a fi")
        raise OSError(28, "No space left on device")

    with pytest.raises(UsageError, match="No space left on device"):
        write_output(out, half_then_full_disk)
    assert out.read_text() == "the good one\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["w.csv"]
    write_output(out, lambda path: path.write_text("the new one\n"))
    assert out.read_text() == "the new one\n" and sorted(p.name for p in tmp_path.iterdir()) == ["w.csv"]


def test_every_command_that_writes_checks_its_output_with_the_one_helper():
    """The one helper (gaitbot.app.outputs), used wherever a command takes an output name."""
    app = REPO_ROOT / "gaitbot" / "app"
    for module in ("generate", "plot", "eigen", "calibrate", "record", "walk"):
        text = (app / f"{module}.py").read_text()
        assert "output_path(" in text, module
    assert "def check_output_path" not in (app / "options.py").read_text()
