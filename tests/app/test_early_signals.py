"""Ctrl-C or SIGTERM while gaitbot is still starting (issue 26.5): the entry point catches signals before it
imports the command line, so one that lands during the imports (about a tenth of a second) or the planning
is one line and exit 130 (143), never a KeyboardInterrupt traceback, and nothing is sent.

The process says when the entry point has installed its handlers; the signal follows after a seeded random
delay of 0 to 150 ms, which spans the imports of the command line and the start of the planning.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import numpy as np
import pytest

from helpers import REPO_ROOT

#: The entry point as the console script runs it, announcing (once) when its handlers are installed: the
#: first thing its ``main`` does. Before that a signal is Python's own business (its start-up, the imports
#: of the console script's line), which no program can guard.
PROGRAM = """
import signal, sys
from gaitbot.app.entry import main
install, announced = signal.signal, []
def announcing(signum, handler):
    old = install(signum, handler)
    if signum == signal.SIGTERM and not announced:
        announced.append(1)
        sys.stderr.write("ready\\n")
        sys.stderr.flush()
    return old
signal.signal = announcing
sys.exit(main(["plan", "--robot", "op3", "--distance", "2.0"]))
"""


def start_then_signal(signum: int, delay_s: float) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(REPO_ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    proc = subprocess.Popen([sys.executable, "-c", PROGRAM], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=env)
    assert proc.stderr.readline() == "ready\n"
    deadline = __import__("time").monotonic() + delay_s
    while __import__("time").monotonic() < deadline:
        pass
    proc.send_signal(signum)
    out, err = proc.communicate(timeout=60)
    return subprocess.CompletedProcess(proc.args, proc.returncode, out, err)


@pytest.mark.parametrize("signum, status", [(signal.SIGINT, 130),
                                            pytest.param(signal.SIGTERM, 143, marks=pytest.mark.slow)])
def test_a_signal_while_starting_is_one_line_and_the_signal_status(signum, status):
    rng = np.random.default_rng(26)
    for delay_s in rng.uniform(0.0, 0.15, size=6):
        run = start_then_signal(signum, float(delay_s))
        assert "Traceback" not in run.stderr, (delay_s, run.stderr)
        if run.returncode == 0:  # the whole plan printed before the signal came: nothing to interrupt
            continue
        assert run.returncode == status, (delay_s, run.returncode, run.stderr)
        lines = [line for line in run.stderr.splitlines() if line.strip()]
        assert len(lines) == 1 and "nothing" in lines[0] and "sent" in lines[0], (delay_s, run.stderr)
