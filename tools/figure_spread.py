"""How far a simulated figure moves when the physics is nudged by rounding-sized amounts (docs/figures.md).

    python tools/figure_spread.py "python tools/robustness.py" --runs 4
    python tools/figure_spread.py "python tools/sim_figures.py" --runs 4

A walk in MuJoCo is chaotic: a different CPU, BLAS or MuJoCo release rounds differently, and a contact that
comes a microsecond earlier changes a walk's drift in its first digit. This script stands in for another
machine: it runs the figure command ``--runs`` times, each time adding a seeded random velocity of 1e-10
(m/s or rad/s: a rounding error of the integration, as another CPU or release makes) to every degree of
freedom at every physics step, and prints, for each simulated figure, the largest change of its numbers in units of their last printed digit
and as a share of their value, and whether any text (a pass, a fall, a direction) changed; a line that failed in both (``**no**``, ``FELL``)
counts up to its mark, as tools/figures.py compares it. The tolerance
of the docs' simulated figures (``SIMULATED`` in tools/figures.py) is set above what this prints.
"""

from __future__ import annotations

import argparse
import os
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

from figures import NUMBER, PRINTED, _decimals, _failed_lines_cut, regions  # noqa: E402

NUDGE = 1e-10
"""The velocity (m/s, rad/s) added to every degree of freedom at every physics step (a standard deviation)."""


SITECUSTOMIZE = f"""
import os
if os.environ.get("GAITBOT_NUDGE_SEED"):
    # the GL backend gaitbot.sim picks, before mujoco is imported: without it mujoco loads GLFW, whose probe
    # starts a Python process that runs this file again, and so on without end
    os.environ.setdefault("MUJOCO_GL", "egl")
    import numpy as np
    import mujoco
    _rng = np.random.default_rng(int(os.environ["GAITBOT_NUDGE_SEED"]))
    _step = mujoco.mj_step

    def _nudged_step(model, data, *args):
        data.qvel[:] += _rng.normal(0.0, {NUDGE!r}, model.nv)
        return _step(model, data, *args)

    mujoco.mj_step = _nudged_step
"""
"""Put first on PYTHONPATH, this makes every Python process of the figure command (the walks it starts too)
nudge MuJoCo's velocities before each step."""


def spread(command: str, runs: int) -> dict[str, tuple[float, float, bool]]:
    """Per figure: the largest change in units of the last digit, the largest relative change, and whether
    the text changed, over ``runs`` nudged runs against the documented figure."""
    documented = {r.name: r.text for r in regions() if r.command == command}
    worst: dict[str, list] = {name: [0.0, 0.0, False] for name in documented}
    argv = [sys.executable, *shlex.split(command)[1:], "--markdown"]
    folder = tempfile.mkdtemp()
    Path(folder, "sitecustomize.py").write_text(SITECUSTOMIZE)
    path = os.pathsep.join(p for p in (folder, os.environ.get("PYTHONPATH", "")) if p)
    for seed in range(runs):
        env = {**os.environ, "PYTHONPATH": path, "GAITBOT_NUDGE_SEED": str(seed + 1),
               "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}"}
        out = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, env=env)
        if out.returncode != 0:
            raise SystemExit(f"run {seed} failed:\n{out.stderr[-2000:]}")
        Path(folder, f"run{seed + 1}.md").write_text(out.stdout)
        fresh = {m.group(1): m.group(2) for m in PRINTED.finditer(out.stdout)}
        for name, documented_text in documented.items():
            text, now = _failed_lines_cut(documented_text, fresh.get(name, ""))
            a, b = NUMBER.findall(text), NUMBER.findall(now)
            if NUMBER.split(text) != NUMBER.split(now) or len(a) != len(b):
                worst[name][2] = True
                continue
            for x, y in zip(a, b):
                unit = 10.0 ** -max(_decimals(x), _decimals(y))
                change = abs(float(x) - float(y))
                worst[name][0] = max(worst[name][0], change / unit)
                worst[name][1] = max(worst[name][1], change / max(abs(float(x)), unit))
    print(f"each run's output: {folder}/run*.md")
    return {name: tuple(w) for name, w in worst.items()}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("command", help='a figure command, e.g. "python tools/robustness.py"')
    parser.add_argument("--runs", type=int, default=4)
    args = parser.parse_args(argv)
    for name, (units, share, text) in spread(args.command, args.runs).items():
        print(f"{name}: numbers moved up to {units:.0f} units of their last digit ({share:.0%} of the value)"
              f"{'; THE TEXT CHANGED' if text else ''}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
