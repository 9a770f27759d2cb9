"""tools/bench_placo.py runs (quick: each scenario a quarter as long) and prints its table: both planners on
every scenario, gaitbot's walk standing in both simulations and keeping its planned ZMP inside the soles."""

import subprocess
import sys

import pytest

from helpers import REPO_ROOT

pytest.importorskip("placo")


@pytest.mark.slow
def test_the_placo_table_has_both_planners_and_gaitbot_walks():
    proc = subprocess.run([sys.executable, "tools/bench_placo.py", "--quick"], capture_output=True, text=True,
                          cwd=REPO_ROOT, timeout=600)
    assert proc.returncode == 0, proc.stderr
    rows = [[c.strip() for c in line.strip("|").split("|")] for line in proc.stdout.splitlines()
            if line.startswith("| ") and not line.startswith("| scenario")]
    assert [(r[0], r[1]) for r in rows] == [(s, p) for s in ("straight 2 m", "turn in place 90 deg", "sidestep 0.2 m")
                                            for p in ("gaitbot", "PlaCo")]
    for r in rows:
        assert int(r[2]) > 0 and float(r[3]) > 0 and float(r[4]) > 0  # steps, ms/step, ms/frame
        if r[1] == "gaitbot":
            assert float(r[5]) > 0 and "FELL" not in r[9] and "FELL" not in r[10]
