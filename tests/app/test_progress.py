"""Long work shows its progress on a terminal, and nothing of it reaches a pipe (docs/command-line.md)."""

from __future__ import annotations

import fcntl
import os
import pty
import select
import struct
import subprocess
import sys
import termios

import pytest

from helpers import CONFIG_DIR, REPO_ROOT


def run_on_a_terminal(*args: str, cwd=REPO_ROOT, timeout: float = 120.0) -> tuple[int, str]:
    """gaitbot with its stderr on a pseudo-terminal (stdout a pipe): (status, all the terminal received)."""
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 40, 120, 0, 0))  # 40 lines of 120 columns
    proc = subprocess.Popen([sys.executable, "-m", "gaitbot", *args], stdout=subprocess.PIPE, stderr=slave,
                            stdin=subprocess.DEVNULL, cwd=cwd)
    os.close(slave)
    seen = b""
    while True:
        ready, _, _ = select.select([master], [], [], timeout)
        if not ready:
            proc.kill()
            break
        try:
            chunk = os.read(master, 65536)
        except OSError:  # the child closed its end
            break
        if not chunk:
            break
        seen += chunk
    os.close(master)
    proc.stdout.read()
    return proc.wait(timeout=timeout), seen.decode(errors="replace")


@pytest.mark.parametrize("args, words", [
    (("walk", "--dry-run", "--realtime", "--steps", "0.02"), ("walking", "Ctrl-C stops safely", "frame")),
    (("plan", "--terrain", str(CONFIG_DIR / "terrain" / "kerb.toml")), ("planning kerb.toml", "step")),
], ids=["real-time walk", "terrain planning"])
@pytest.mark.slow
def test_long_work_shows_its_progress_on_a_terminal(args, words):
    status, terminal = run_on_a_terminal(*args)
    assert status == 0, terminal
    for word in words:
        assert word in terminal, terminal


@pytest.mark.slow
def test_eigen_fit_shows_its_progress_on_a_terminal(tmp_path):
    from gaitbot.app.cli import main

    for step in (0.03, 0.07):
        assert main(["generate", "--steps", f"{step},{step},{step},{step}", "-o", str(tmp_path / f"e{step}.npz")]) == 0
    status, terminal = run_on_a_terminal("eigen", "fit", "e0.03.npz", "e0.07.npz", "-o", "m.npz", cwd=tmp_path)
    assert status == 0, terminal
    assert "aligning cycles" in terminal and "cycle" in terminal


@pytest.mark.parametrize("args", [("walk", "--dry-run", "--steps", "0.02"),
                                  pytest.param(("plan", "--terrain", str(CONFIG_DIR / "terrain" / "kerb.toml")),
                                               marks=pytest.mark.slow)])
def test_nothing_of_it_when_stderr_is_not_a_terminal(args):
    proc = subprocess.run([sys.executable, "-m", "gaitbot", *args], capture_output=True, text=True, cwd=REPO_ROOT,
                          timeout=120)
    assert proc.returncode == 0
    assert "\r" not in proc.stderr and "%|" not in proc.stderr and "Ctrl-C stops" not in proc.stderr
