"""What the hips could add to the push survival if the push were known: an oracle's hip burst, in the simulation.

    python tools/push_hips_oracle.py              # tools/push_survival.py's 100 pushes, op3, feedback full,
                                                  # without and with the burst at each latency (about 9 min)
    python tools/push_hips_oracle.py --markdown   # docs/capturability.md's figure

tools/push_capturability.py counts 95 of the 100 pushes capturable once the hips' allowance is added (a torso
swung at full torque and speed from the push's first instant), and 85 without it; the feedback survives 69.
This asks the simulation the same question. Each push is walked as tools/push_survival.py walks it (same draw,
same IMU seed, feedback full), and a push of more than OVER_N_S gets a hip burst: both hip pitch goals and the
hip roll goals (left +, right -: the torso turned toward the push about the stance hip, whichever foot
stands) moved by BURST_DEG along the push's direction, held HOLD_S, then back over RETURN_S; the goals still
pass the session's limit guard (gaitbot.feel.feedback). The burst is an oracle's: it is told the push's time,
size and direction by the simulation (the IMU's reading is never used for it), LATENCY_FRAMES after the push
starts (2 frames is the soonest the IMU's one-frame delay lets any reading show it). So its count is an upper
bound on what a burst triggered by the IMU could add with the same shape, and the latencies say what
noticing a push later costs. A burst for every push, whatever its size, is the last row: knowing the size
matters too.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import sys
from concurrent.futures import ProcessPoolExecutor

import numpy as np

import push_survival
from gaitbot.feel.feedback import Feedback
from gaitbot.robot.config import load_robot_config
from gaitbot.robot.shipped_configs import resolve_config
from gaitbot.sim.walk import SimWalk

BURST_DEG = 30.0
"""How far each hip goal moves (deg), along the push's direction: the allowance's 30 deg of torso swing."""
HOLD_S = 0.15
"""How long the goals stay moved (s): about the allowance's swing of 30 deg (0.14 s at the joints' speed limit,
tools/push_capturability.py's hip_allowance_m)."""
RETURN_S = 0.5
"""How long they take to come back (s): slower than the swing, so that the way back (which the allowance leaves
out) undoes less of what it caught."""
OVER_N_S = 1.2
"""The pushes given a burst: the bound's 15 lost pushes without the hips are all of 1.39 N s or more."""
LATENCY_FRAMES = (2, 3, 4, 6)
"""When the burst starts after the push does (frames of the op3's goal stream)."""
FRAME_S = 1.0 / load_robot_config(resolve_config("op3")).gait.rate_hz
DRAWS = push_survival.drawn_pushes(100, 23, 2.0)
"""tools/push_survival.py's pushes (its defaults: 100 of 0 to 2 N s, seed 23)."""
WORKERS = 2
"""Processes walking the pushes (the machines this runs on have two cores)."""


def burst_share(t_s: float, start_s: float) -> float:
    """How much of the burst acts at ``t_s`` (0 before ``start_s``, 1 for HOLD_S, then down to 0 over RETURN_S)."""
    after = t_s - start_s
    if after < 0.0 or after >= HOLD_S + RETURN_S:
        return 0.0
    return 1.0 if after < HOLD_S else 1.0 - (after - HOLD_S) / RETURN_S


def burst_rad(names: list[str], direction_deg: float, share: float) -> np.ndarray:
    """Each joint's move (rad) for a burst toward ``direction_deg`` (from forward, counter-clockwise) at
    ``share``: the hip pitches by cos, hip_roll_left by +sin and hip_roll_right by -sin of the direction (the
    configs' signs: pitch flexion positive, roll abduction positive)."""
    size = math.radians(BURST_DEG) * share
    pitch, roll = size * math.cos(math.radians(direction_deg)), size * math.sin(math.radians(direction_deg))
    moves = {"hip_pitch_left": pitch, "hip_pitch_right": pitch, "hip_roll_left": roll, "hip_roll_right": -roll}
    return np.array([moves.get(name, 0.0) for name in names])


@contextlib.contextmanager
def oracle(latency_frames: int | None, over_n_s: float = OVER_N_S):
    """While inside, each simulated walk's push of more than ``over_n_s`` gets the burst, ``latency_frames``
    after it starts (None: no burst). The simulation tells the walk's Feedback about the push; the burst is
    added to the planned goals before Feedback.correct, so its own corrections and limit guard apply."""
    told = {}
    sim_init, correct = SimWalk.__init__, Feedback.correct

    def sim_walk_init(self, *args, **kwargs):
        sim_init(self, *args, **kwargs)
        push = self.push
        told["push"] = push if push is not None and push.impulse_n_s > over_n_s else None

    def burst_correct(self, k, row):
        push = told.get("push")
        if latency_frames is None or push is None:
            return correct(self, k, row)
        share = burst_share(self.now() - self.start_s, push.start_s + latency_frames * FRAME_S)
        moved = np.asarray(row, dtype=float) + burst_rad(self.names, push.direction_deg, share) * self.ticks_per_rad
        return correct(self, k, moved)

    SimWalk.__init__, Feedback.correct = sim_walk_init, burst_correct
    try:
        yield
    finally:
        SimWalk.__init__, Feedback.correct = sim_init, correct


def _walk(task: tuple) -> bool:
    """One push of tools/push_survival.py (op3, feedback full) walked with the oracle: survived?"""
    latency_frames, over_n_s, n, (impulse, direction, phase) = task
    with oracle(latency_frames, over_n_s):
        return push_survival.one_push("op3", push_survival.WALKS["op3"], impulse, direction, phase, n, "full")["survived"]


def survived(runs: list[tuple[int | None, float]]) -> list[list[bool]]:
    """For each (latency_frames, over_n_s) of ``runs``, each of DRAWS: survived? The walks are independent (each
    its own session and seeded IMU): WORKERS processes walk them, in any order."""
    tasks = [(latency, over, n, draw) for latency, over in runs for n, draw in enumerate(DRAWS, start=1)]
    with ProcessPoolExecutor(WORKERS) as pool:
        alive = list(pool.map(_walk, tasks, chunksize=4))
    return [alive[i * len(DRAWS):(i + 1) * len(DRAWS)] for i in range(len(runs))]


def markdown() -> str:
    big = [impulse > OVER_N_S for impulse, _, _ in DRAWS]
    labels = ["none (feedback full as shipped)"]
    labels += [f"{n} frames ({1e3 * n * FRAME_S:.0f} ms) after the push" for n in LATENCY_FRAMES]
    labels.append(f"every push, whatever its size: {LATENCY_FRAMES[0]} frames after it")
    runs = [(None, OVER_N_S), *((n, OVER_N_S) for n in LATENCY_FRAMES), (LATENCY_FRAMES[0], 0.0)]
    rows = list(zip(labels, survived(runs)))
    lines = [f"| hip burst ({BURST_DEG:g} deg, pushes over {OVER_N_S:g} N s), started | survived of {len(DRAWS)} | "
             f"of the {sum(big)} over {OVER_N_S:g} N s | of the {len(DRAWS) - sum(big)} others |", "|---|---|---|---|"]
    for label, alive in rows:
        lines.append(f"| {label} | {sum(alive)} | {sum(a for a, b in zip(alive, big) if b)} | "
                     f"{sum(a for a, b in zip(alive, big) if not b)} |")
    return "<!-- figure push-hips-oracle -->\n" + "\n".join(lines) + "\n<!-- /figure -->"


def main_(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", action="store_true", help="print the docs' figure (tools/figures.py)")
    parser.parse_args(argv)
    print(markdown())
    return 0


if __name__ == "__main__":
    sys.exit(main_())
