"""What any controller could catch: N-step capturability of the push-survival pushes on a linear inverted pendulum.

    python tools/push_capturability.py              # the 100 pushes of tools/push_survival.py, op3: a row each
    python tools/push_capturability.py --markdown   # the docs' figures (docs/capturability.md, docs/feedback.md)
    python tools/push_capturability.py --json       # one JSON object per push

An upper bound on push survival, computed, not simulated (Koolen et al., "Capturability-based analysis and
control of legged locomotion", IJRR 2012; Pratt et al., "Capture point: a step toward humanoid push
recovery", 2006). The robot is a linear inverted pendulum of the robot's total mass at the planned CoM's
height z_c; its divergent component of motion (capture point) xi = c + c_dot / omega, omega = sqrt(g / z_c),
obeys xi_dot = omega (xi - p) + F / (m omega): p the ZMP, F the push (impulse / PUSH_DURATION_S for 0.1 s).
The state at the push is the planned walk's (gaitbot's balanced walker, the same plan ``gaitbot walk --sim``
walks): the CoM and its velocity, the feet where they are, which foot swings and when it lands. The pushes
are tools/push_survival.py's (same seed, impulse, direction, phase).

The idealised controller:
- the ZMP anywhere in the support polygon, instantly (both soles' hull while both are down);
- the swinging (or next) foot lands at its planned time or earlier, no sooner than the rest of its swing
  played faster by the most the servos allow: the plan's peak joint velocity share s_v and acceleration
  share s_a (of max_velocity_dps, max_acceleration_dps2) allow a time scale 1 / max(s_v, sqrt(s_a))
  (``speedup``); LANDING_SAMPLES landing times from that to the planned one are tried;
- later steps at the plan's cadence (a step period after the one before, the plan's double support after
  each landing); after its last step (up to MAX_STEPS) the robot stands on both feet: xi must then be in
  their hull (N-step capturability; N = 0: no step, the feet on the floor hold it);
- each foothold, in the stance foot's frame, within (a) the robot's ``[steer]`` per-step limits (forward
  the larger of max_forward_m and the plan's own step, backward max_backward_m, outward max_side_m beyond
  the hip width), or (b) the leg's kinematic reach (each ankle a straight leg's horizontal reach R from its
  hip at the walking height, the hips between the feet: 2 R forward, backward and outward); in both, never
  across the other foot: the soles' inner edges at least ``[steer] min_gap_m`` apart;
- and, in the columns "and the hips", the torso swung about the hips as a flywheel (``hip_allowance_m``).
The push acts from the first frame end at or after its start, as the simulation's Pusher applies it. The x
(forward) and y (sideways) problems separate (box soles, box step limits): each is a small linear program in
the footholds, solved for the same N and landing time. The hull of two soles is taken as its
bounding box, a little generous, as befits an upper bound. Why a push is not capturable: the axis that
cannot be caught, and which one constraint lifted would catch it (the step limits: reach instead; the feet's
gap: crossing allowed; the servos' speed: landing at once).
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import sys
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy.optimize import linprog

from gaitbot.gait.joints import LEG_JOINTS
from gaitbot.gait.mass import GRAVITY_M_S2
from gaitbot.robot.calibration import full_angles_rad
from gaitbot.robot.joint_motion import limit_shares
from gaitbot.sim.walk import PUSH_DURATION_S

MAX_STEPS = 3
LANDING_SAMPLES = 5
MENAGERIE_WALK = "--distance 1 --max-step 0.05 --cycle 1.0"
MENAGERIE_PUSHES = ((1.5, 90.0), (1.5, 0.0))
LEFT, RIGHT = "left", "right"
SIGN = {LEFT: 1.0, RIGHT: -1.0}


@dataclass(frozen=True)
class StepBox:
    """Where a foothold may go, in the stance foot's frame (m): forward / backward of it, and its sideways
    spread (the new ankle's distance from the stance ankle, outward positive) between spread_min_m and spread_max_m."""

    forward_m: float
    backward_m: float
    spread_min_m: float
    spread_max_m: float


@dataclass(frozen=True)
class Situation:
    """The walk at the push, in the walk's world (x forward, y left; m, s): the capture point xi0_m, omega, the
    mass, the feet's ankle points, the stance foot, the other foot (swinging, or down until lift_s), its
    planned landing, the step period and double support after a landing, the servos' speed-up, the soles."""

    t_s: float
    xi0_m: tuple[float, float]
    omega: float
    mass_kg: float
    feet_m: dict
    stance: str
    lift_s: float | None  # the other foot lifts then (it is down at the push; inf: never), None: it swings already
    land_s: float | None  # its planned landing; None: no step planned (standing)
    step_s: float
    double_s: float
    speedup: float
    sole_x_m: tuple[float, float]  # the sole's back and front edge from the ankle point (x)
    sole_y_m: dict  # side -> the sole's right and left edge from the ankle point (y)

    @property
    def swing(self) -> str:
        return RIGHT if self.stance == LEFT else LEFT

    def side_of(self, k: int) -> str:
        """The side of foot k: 0 the stance foot, -1 the other foot where it is, k >= 1 the k-th landing."""
        return self.stance if k == 0 or (k > 0 and k % 2 == 0) else self.swing


def sole_edges(geometry) -> tuple[tuple[float, float], dict]:
    """The sole box's edges from the ankle point: (back, front) in x, and per side (right, left) in y."""
    x = (-geometry.heel_back_m, geometry.foot_m - geometry.heel_back_m)
    half, out = geometry.foot_width_m / 2, geometry.sole_outward_m
    return x, {LEFT: (out - half, out + half), RIGHT: (-out - half, -out + half)}


def push_shift_m(sit: Situation, impulse_n_s: float, duration_s: float = PUSH_DURATION_S) -> float:
    """How far a push of ``impulse_n_s`` over ``duration_s`` moves the capture point, referred to the push's
    start (the ZMP's part aside): F / (m omega^2) (1 - exp(-omega T)), -> J / (m omega) as T -> 0."""
    w = sit.omega
    if duration_s <= 0:
        return impulse_n_s / (sit.mass_kg * w)
    return impulse_n_s / duration_s / (sit.mass_kg * w * w) * (1.0 - math.exp(-w * duration_s))


def timeline(sit: Situation, steps: int, first_land_s: float, push_end_s: float):
    """The support over time for ``steps`` landings, the first at ``first_land_s``: segments (start, end,
    feet) and the final feet (foot ids as Situation.side_of), and the end time."""
    segs = []
    if steps == 0:
        feet = (0,) if sit.lift_s is None else (0, -1)
        return [(sit.t_s, push_end_s, feet)], feet, push_end_s
    t = sit.t_s
    if sit.lift_s is not None and sit.lift_s > t:
        segs.append((t, sit.lift_s, (0, -1)))
        t = sit.lift_s
    lands = [first_land_s + k * sit.step_s for k in range(steps)]
    segs.append((t, lands[0], (0,)))
    for k in range(1, steps):
        ds_end = min(lands[k - 1] + sit.double_s, lands[k])
        segs.append((lands[k - 1], ds_end, (k - 1, k)))
        segs.append((ds_end, lands[k], (k,)))
    end = max(lands[-1], push_end_s)
    final = (steps - 1, steps)
    if end > lands[-1]:
        segs.append((lands[-1], end, final))
    return [s for s in segs if s[1] > s[0]], final, end


def _bounds(sit: Situation, axis: int, feet, order, n_vars: int):
    """The lower and upper edge of the support of ``feet`` on ``axis`` as (coefficients on the footholds,
    constant): one foot's sole, or the hull of two with ``order`` (which foot gives the lower edge) chosen."""
    def edge(k: int, which: int):
        coef = np.zeros(n_vars)
        off = sit.sole_x_m[which] if axis == 0 else sit.sole_y_m[sit.side_of(k)][which]
        if k >= 1:
            coef[k - 1] = 1.0
            return coef, off
        key = sit.stance if k == 0 else sit.swing
        return coef, sit.feet_m[key][axis] + off
    if len(feet) == 1:
        return edge(feet[0], 0), edge(feet[0], 1)
    if max(feet) < 1:  # both feet fixed (the push came in double support): the exact hull
        lo = min(edge(k, 0)[1] for k in feet)
        hi = max(edge(k, 1)[1] for k in feet)
        return (np.zeros(n_vars), lo), (np.zeros(n_vars), hi)
    lower, upper = (feet[0], feet[1]) if order else (feet[1], feet[0])
    return edge(lower, 0), edge(upper, 1)


def _step_rows(sit: Situation, axis: int, steps: int, box: StepBox):
    """The footholds' limits as rows A f <= b."""
    rows, rhs = [], []
    for k in range(1, steps + 1):
        coef = np.zeros(steps)
        coef[k - 1] = 1.0
        if k >= 2:
            coef[k - 2] = -1.0
            base = 0.0
        else:
            base = sit.feet_m[sit.stance][axis]
        if axis == 0:
            hi, lo = box.forward_m, -box.backward_m
        else:
            s = SIGN[sit.side_of(k)]
            coef = s * coef
            base = s * base
            hi, lo = box.spread_max_m, box.spread_min_m
        rows += [coef, -coef]
        rhs += [hi + base, -(lo + base)]
    return rows, rhs


def axis_capturable(sit: Situation, axis: int, steps: int, first_land_s: float, box: StepBox,
                    shift_m: float, duration_s: float = PUSH_DURATION_S, hip_m: float = 0.0) -> bool:
    """Whether some footholds (within ``box``) and ZMP keep this axis's capture point caught: the linear
    program of the module docstring (the ZMP's weighted means over the segments eliminated); ``hip_m``: how
    far the torso's swing may move the capture point back (referred to the push's start; hip_allowance_m)."""
    push_end = sit.t_s + duration_s
    segs, final, end = timeline(sit, steps, first_land_s, push_end)
    w = sit.omega
    weights = [math.exp(-w * (a - sit.t_s)) - math.exp(-w * (b - sit.t_s)) for a, b, _ in segs]
    tail = math.exp(-w * (end - sit.t_s))
    x0 = sit.xi0_m[axis] + shift_m
    step_a, step_b = _step_rows(sit, axis, steps, box)
    pairs = sorted({feet for *_, feet in [*segs, (0, 0, final)] if len(feet) == 2 and max(feet) >= 1})
    choices = [(True, False)] * len(pairs)
    if axis == 1 and box.spread_min_m > 0:  # the feet cannot cross: the left sole's edges are the left ones
        choices = [(sit.side_of(p[0]) == RIGHT,) for p in pairs]
    for orders in itertools.product(*choices):
        order_of = dict(zip(pairs, orders))
        lo_sum, hi_sum = np.zeros(steps), np.zeros(steps)
        lo_c = hi_c = 0.0
        for weight, (_, _, feet) in zip(weights, segs):
            (lc, lk), (uc, uk) = _bounds(sit, axis, feet, order_of.get(feet, True), steps)
            lo_sum, lo_c = lo_sum + weight * lc, lo_c + weight * lk
            hi_sum, hi_c = hi_sum + weight * uc, hi_c + weight * uk
        (flc, flk), (fuc, fuk) = _bounds(sit, axis, final, order_of.get(final, True), steps)
        # x0 - sum W U <= tail * U_final and tail * L_final <= x0 - sum W L
        rows = step_a + [-hi_sum - tail * fuc, lo_sum + tail * flc]
        rhs = step_b + [tail * fuk + hi_c - x0 + hip_m, x0 - lo_c - tail * flk + hip_m]
        if _feasible(np.array(rows).reshape(len(rows), steps), np.array(rhs), steps):
            return True
    return False


def _feasible(a_ub: np.ndarray, b_ub: np.ndarray, n: int) -> bool:
    if n == 0:
        return bool(np.all(b_ub >= -1e-12))
    res = linprog(np.zeros(n), A_ub=a_ub, b_ub=b_ub, bounds=[(None, None)] * n, method="highs")
    return res.status == 0


def landing_times(sit: Situation, immediate: bool = False) -> list[float]:
    """The first landing's times tried: from the earliest the servos allow (``speedup``; ``immediate``: at
    once) to the planned one."""
    start = sit.t_s if sit.lift_s is None else max(sit.t_s, sit.lift_s)
    earliest = start if immediate else start + (sit.land_s - start) / sit.speedup
    return list(np.linspace(earliest, sit.land_s, LANDING_SAMPLES))


def capturable(sit: Situation, impulse_n_s: float, direction_deg: float, box: StepBox,
               immediate: bool = False, duration_s: float = PUSH_DURATION_S, hip_m=(0.0, 0.0)) -> dict:
    """Whether the push is caught: with N = 0..MAX_STEPS steps and some landing time, both axes at once.
    Returns {"ok", "steps", "axes_alone"} (axes_alone: whether each axis alone could be caught)."""
    shift = push_shift_m(sit, impulse_n_s, duration_s)
    a = math.radians(direction_deg)
    shifts = (shift * math.cos(a), shift * math.sin(a))
    alone = [False, False]
    plans = [(0, sit.t_s)]
    if sit.land_s is not None:
        plans += [(n, t) for n in range(1, MAX_STEPS + 1) for t in landing_times(sit, immediate)]
    for n, t in plans:
        ok = [axis_capturable(sit, axis, n, t, box, shifts[axis], duration_s, hip_m[axis]) for axis in (0, 1)]
        alone = [x or y for x, y in zip(alone, ok)]
        if all(ok):
            return {"ok": True, "steps": n, "axes_alone": alone}
    return {"ok": False, "steps": None, "axes_alone": alone}


# --------------------------------------------------------------------------- the plan's state at a push

@dataclass(frozen=True)
class PlannedState:
    """A planned walk as the analysis reads it: the robot config, the balanced walk's arrays, its swing
    windows (gaitbot.sim.walk.WalkPlan, for the pushes' times) and its speed fit's crouch."""

    config: object
    walk: object
    sim_plan: object
    crouch_knee_deg: float


def plan_walk(robot: str, walk_args: str) -> PlannedState:
    """The walk ``gaitbot walk --sim --robot ROBOT WALK_ARGS`` walks, planned by gaitbot's own planner (the
    same plan with or without ``--sim``: the simulation changes the bus, not the plan)."""
    from gaitbot.app.cli import build_parser
    from gaitbot.app.planned_walk import planned_walk
    from gaitbot.sim.walk import walk_plan

    args = build_parser().parse_args(["walk", "--robot", robot, *walk_args.split()])
    planned = planned_walk(args)
    return PlannedState(planned.source.robot, planned.plan.walk, walk_plan(planned.plan, planned.planned),
                        planned.plan.fit.balance.crouch_knee_deg)


def _swing_edges(swinging: np.ndarray, rate_hz: float) -> list[tuple[str, float, float]]:
    """Every swing of the walk: (side, lift-off s, landing s), as gaitbot.sim.walk.swing_windows times them
    (frame k holds the pose at k / rate; a swing over frames a..b-1 spans ((a - 1) / rate, (b - 1) / rate])."""
    edges = np.flatnonzero(np.diff(np.r_[0, swinging, 0]))
    out = []
    for a, b in zip(edges[:-1], edges[1:]):
        if swinging[a]:
            out.append((LEFT if swinging[a] == 1 else RIGHT, (a - 1) / rate_hz, (b - 1) / rate_hz))
    return out


def speedup(config, walk) -> float:
    """How much faster than planned the rest of a swing may be played within the joints' limits: played k times
    faster, its joint velocities scale by k and accelerations by k^2, so k = 1 / max(velocity share,
    sqrt(acceleration share)), the plan's peak shares of max_velocity_dps and max_acceleration_dps2."""
    rate = 1.0 / (walk.t_s[1] - walk.t_s[0])
    t = np.arange(len(walk.q_rad)) / rate
    v, a = limit_shares(config, t, np.degrees(full_angles_rad(config, walk.q_rad, LEG_JOINTS)))
    return 1.0 / max(float(v.max()), math.sqrt(float(a.max())))


def situation_at(state: PlannedState, t_s: float, mass_kg: float | None = None) -> Situation:
    """The walk's state at ``t_s`` (the push's start) for the analysis."""
    walk, config = state.walk, state.config
    rate = 1.0 / (walk.t_s[1] - walk.t_s[0])
    k = min(int(math.floor(t_s * rate)), len(walk.t_s) - 2)
    u = t_s * rate - k
    com = (1 - u) * walk.com_m[k] + u * walk.com_m[k + 1]
    com_v = (walk.com_m[k + 1] - walk.com_m[k]) * rate
    omega = math.sqrt(GRAVITY_M_S2 / com[2])
    swings = _swing_edges(walk.swinging, rate)
    now = [s for s in swings if s[1] < t_s <= s[2]]
    later = [s for s in swings if s[1] >= t_s]
    nxt = now[0] if now else (later[0] if later else None)
    lands = np.array([s[2] for s in swings])
    lifts = np.array([s[1] for s in swings])
    step_s = float(np.median(np.diff(lands))) if len(lands) > 1 else config.gait.cycle_s / 2
    double_s = float(np.median(lifts[1:] - lands[:-1])) if len(lands) > 1 else 0.0
    swing = nxt[0] if nxt else LEFT
    stance = RIGHT if swing == LEFT else LEFT
    feet = {side: tuple(float(v) for v in walk.ankles_m[k, i, :2]) for i, side in enumerate((LEFT, RIGHT))}
    sole_x, sole_y = sole_edges(config.body.geometry)
    return Situation(t_s=t_s, xi0_m=(float(com[0] + com_v[0] / omega), float(com[1] + com_v[1] / omega)),
                     omega=omega, mass_kg=mass_kg or config.body.total_kg, feet_m=feet, stance=stance,
                     lift_s=None if (now or nxt is None) else nxt[1], land_s=nxt[2] if nxt else None,
                     step_s=step_s, double_s=double_s, speedup=speedup(config, walk), sole_x_m=sole_x,
                     sole_y_m=sole_y)


def steer_box(state: PlannedState) -> StepBox:
    """(a): the ``[steer]`` per-step limits (forward: the larger of max_forward_m and the plan's own step)."""
    config = state.config
    g, lim = config.body.geometry, config.steer
    plan_step = float(np.max(np.abs(np.diff([h.x_m for h in state.walk.heel_strikes])), initial=0.0))
    return StepBox(max(lim.max_forward_m, plan_step), lim.max_backward_m, _spread_min(config),
                   g.hip_width_m + lim.max_side_m)


def reach_m(state: PlannedState) -> float:
    """A straight leg's horizontal reach from its hip at the walking crouch's hip height."""
    from gaitbot.gait.balance.step_plan import crouch_hip_height_m

    g = state.config.body.geometry
    h = crouch_hip_height_m(g, state.crouch_knee_deg)
    return math.sqrt(max((g.thigh_m + g.shank_m) ** 2 - h * h, 0.0))


def reach_box(state: PlannedState) -> StepBox:
    """(b): the legs' kinematic reach, 2 R each way (R: reach_m), the feet never across each other."""
    r = reach_m(state)
    return StepBox(2 * r, 2 * r, _spread_min(state.config), state.config.body.geometry.hip_width_m + 2 * r)


def _spread_min(config) -> float:
    """The least sideways spread of the ankles keeping the soles' inner edges min_gap_m apart."""
    g = config.body.geometry
    return g.foot_width_m - 2 * g.sole_outward_m + config.steer.min_gap_m


HIP_LEAN_DEG = 30.0
"""The torso's swing the hip allowance grants, each way, in pitch and in roll: inside the hip joints' range at the
walking crouch, and under the op3's fall threshold (40 deg of tilt)."""


def hip_allowance_m(config, omega: float) -> tuple[float, float]:
    """How far swinging the torso about the hips could move the capture point back (m; x by the hip pitch
    joints, y by the hip roll joints), referred to the push's start: Pratt et al.'s flywheel (the torso a
    wheel at the CoM, its torque tau moving the centroidal moment pivot tau / (m g) from the ZMP). Both hips'
    stall torque, the joints' speed and acceleration limits, a swing of HIP_LEAN_DEG stopped at its end: a
    bang-coast-bang profile, the pivot moved +tau / (m g) while the torso speeds up (t_a) and back while it
    stops (from t_b): tau / (m g) ((1 - e^(-w t_a)) - (e^(-w t_b) - e^(-w (t_b + t_a)))). Generous: applied at
    the push's start, and the torso's way back upright (which undoes it) left out."""
    torso, joints = config.body.torso, {j.name: j for j in config.joints}
    hip_height = config.body.geometry.hip_below_root_m
    d = np.asarray(torso.com_m) + [0.0, 0.0, hip_height]  # the torso's CoM from the hips' midpoint
    out = []
    for axis, joint in ((1, "hip_pitch_left"), (0, "hip_roll_left")):  # pitch turns about y, roll about x
        j = joints[joint]
        inertia = torso.inertia_kg_m2[axis, axis] + torso.mass_kg * (float(d @ d) - d[axis] ** 2)
        torque = 2 * (config.servo.stall_torque_nm or j.model.stall_torque_nm)
        accel = min(torque / inertia, math.radians(j.max_acceleration_dps2))
        rate = math.radians(j.max_velocity_dps)
        lean = math.radians(HIP_LEAN_DEG)
        t_a = min(rate / accel, math.sqrt(lean / accel))
        t_b = lean / (accel * t_a)  # the swing's area: accel t_a (t_b - t_a) + accel t_a^2 = lean
        pivot = accel * inertia / (config.body.total_kg * GRAVITY_M_S2)
        out.append(pivot * ((1 - math.exp(-omega * t_a)) - (math.exp(-omega * t_b) - math.exp(-omega * (t_b + t_a)))))
    return out[0], out[1]


def crossing(box: StepBox) -> StepBox:
    """The same limits with the feet allowed across each other (a reason's test, not a robot's step)."""
    return replace(box, spread_min_m=-box.spread_max_m)


# --------------------------------------------------------------------------- verdicts, reasons, the table

AXES = ("forward-backward", "sideways")


def verdict(sit: Situation, impulse: float, direction: float, box: StepBox, relaxations: dict,
            hip_m=(0.0, 0.0)) -> dict:
    """Capturable or not; if not, the axis that cannot be caught and which one relaxation would catch it."""
    result = capturable(sit, impulse, direction, box, hip_m=hip_m)
    if result["ok"]:
        return {"capturable": True, "steps": result["steps"], "why": None}
    axes = [name for name, ok in zip(AXES, result["axes_alone"]) if not ok] or ["both at one timing"]
    helps = [name for name, (other, immediate) in relaxations.items()
             if capturable(sit, impulse, direction, other, immediate=immediate, hip_m=hip_m)["ok"]]
    return {"capturable": False, "steps": None,
            "why": " and ".join(axes) + ("; caught with " + " or ".join(helps) + " lifted" if helps else "")}


def relaxations_of(state: PlannedState, box: StepBox, reach: bool) -> dict:
    """The single relaxations a reason tries: the step limits (reach instead), the gap, the timing."""
    out = {} if reach else {"the step limits": (reach_box(state), False)}
    out["the feet's gap"] = (crossing(box), False)
    out["the servos' speed"] = (box, True)
    return out


def draws(pushes: int, seed: int, max_impulse: float) -> list[tuple[float, float, float]]:
    """tools/push_survival.py's pushes: (impulse N s, direction deg, phase), the same draws."""
    from push_survival import drawn_pushes

    return drawn_pushes(pushes, seed, max_impulse)


def push_time_s(state: PlannedState, phase: float) -> float:
    """When tools/push_survival.py's push of this phase acts (``gaitbot walk --sim --push-phase``'s start)."""
    from gaitbot.sim.walk import mid_walk_push

    return acting_from_s(state, mid_walk_push(state.sim_plan, 0.0, phase=phase).start_s)


def acting_from_s(state: PlannedState, start_s: float) -> float:
    """When a push starting at ``start_s`` acts in the simulation: gaitbot.sim.walk.Pusher sets its force at
    frame ends, so from the first frame end at or after the start."""
    rate = 1.0 / (state.walk.t_s[1] - state.walk.t_s[0])
    return math.ceil(start_s * rate - 1e-9) / rate


def analyse(state: PlannedState, impulse: float, direction: float, t_s: float, mass_kg: float | None = None) -> dict:
    """One push under (a) the step limits and (b) the legs' reach, each without and with the hip allowance."""
    sit = situation_at(state, t_s, mass_kg)
    hip = hip_allowance_m(state.config, sit.omega)
    out = {}
    for key, box, reach in (("a", steer_box(state), False), ("b", reach_box(state), True)):
        relax = relaxations_of(state, box, reach)
        out[key] = verdict(sit, impulse, direction, box, relax)
        out[key + "_hip"] = verdict(sit, impulse, direction, box, relax, hip)
    return out


def menagerie_mass_kg() -> float:
    """The total mass of MuJoCo Menagerie's OP3 (tools/op3_menagerie.py's model, loaded by MuJoCo)."""
    from gaitbot.sim import import_mujoco

    mujoco = import_mujoco()  # with an offscreen GL backend chosen: a plain import would probe GLFW
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from op3_menagerie import menagerie_mjcf

    model = mujoco.MjModel.from_xml_string(menagerie_mjcf())
    return float(model.body_mass.sum())


def menagerie_rows(robot: str) -> list[dict]:
    """The two Menagerie pushes: mid-swing of the middle step of MENAGERIE_WALK, Menagerie's mass."""
    from gaitbot.sim.walk import mid_walk_push

    state = plan_walk(robot, MENAGERIE_WALK)
    mass = menagerie_mass_kg()
    rows = []
    for impulse, direction in MENAGERIE_PUSHES:
        t = acting_from_s(state, mid_walk_push(state.sim_plan, impulse, direction).start_s)
        rows.append({"impulse_n_s": impulse, "direction_deg": direction, "start_s": round(t, 3),
                     "mass_kg": round(mass, 4), **analyse(state, impulse, direction, t, mass)})
    return rows


def _cell(v: dict) -> str:
    if not v["capturable"]:
        return f"no ({v['why']})"
    return f"yes ({v['steps']} step{'' if v['steps'] == 1 else 's'})"


def table_rows(args) -> list[dict]:
    from push_survival import WALKS

    state = plan_walk(args.robot, WALKS[args.robot])
    rows = []
    for n, (impulse, direction, phase) in enumerate(draws(args.pushes, args.seed, args.max_impulse), start=1):
        row = analyse(state, impulse, direction, push_time_s(state, phase))
        rows.append({"push": n, "impulse_n_s": round(impulse, 3), "direction_deg": round(direction, 1),
                     "phase": round(phase, 3), **row})
    return rows


def markdown(args, rows: list[dict], menagerie: list[dict]) -> str:
    """The docs' figures: capturable pushes per quarter of the impulse range (docs/capturability.md), why the
    others are not and the two Menagerie pushes (the same page), and one sentence (docs/feedback.md)."""
    edges = np.linspace(0, args.max_impulse, 5)
    keys = ("a", "a_hip", "b", "b_hip")
    counts = np.zeros((4, 1 + len(keys)), dtype=int)
    for row in rows:
        q = min(int(row["impulse_n_s"] / args.max_impulse * 4), 3)
        counts[q] += (1, *(row[k]["capturable"] for k in keys))
    out = ["| impulse N s | pushes | (a) step limits | (a) and the hips | (b) legs' reach | (b) and the hips |",
           "|---|---|---|---|---|---|"]
    out += [f"| {edges[q]:g} to {edges[q + 1]:g} | " + " | ".join(str(c) for c in counts[q]) + " |" for q in range(4)]
    total = counts.sum(axis=0)
    out.append("| all | " + " | ".join(str(c) for c in total) + " |")
    why = ["| not capturable under | why (the axis; the one constraint that, lifted, would catch it) | pushes |",
           "|---|---|---|"]
    for key, name in (("a", "(a)"), ("b", "(b)")):
        whys: dict = {}
        for row in rows:
            if not row[key]["capturable"]:
                whys[row[key]["why"]] = whys.get(row[key]["why"], 0) + 1
        ranked = sorted(whys.items(), key=lambda kv: (-kv[1], kv[0]))
        why += [f"| {name} | {text} | {count} |" for text, count in ranked]
    why += ["", "| Menagerie's OP3 push | (a) step limits | (a) and the hips | (b) legs' reach |", "|---|---|---|---|"]
    why += [f"| {m['impulse_n_s']:g} N s at {m['direction_deg']:g} deg | {_cell(m['a'])} | {_cell(m['a_hip'])} | "
            f"{_cell(m['b'])} |" for m in menagerie]
    summary = (f"Under the robot's step limits, steps and ankles catch at most {total[1]} of the {total[0]} pushes "
               f"({total[2]} with the torso swung at the hips' limits as well); within the legs' reach, {total[3]}.")
    return "\n".join(f"<!-- figure {name} -->\n{text}\n<!-- /figure -->" for name, text in (
        ("push-capturability", "\n".join(out)), ("push-capturability-why", "\n".join(why)),
        ("push-capturability-summary", summary)))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="op3", choices=("op3",))
    parser.add_argument("--pushes", type=int, default=100)
    parser.add_argument("--max-impulse", type=float, default=2.0)
    parser.add_argument("--seed", type=int, default=23)
    parser.add_argument("--max-steps", type=int, default=MAX_STEPS, choices=range(0, 6), metavar="N",
                        help=f"the most steps a capture may take (0..5; default {MAX_STEPS})")
    parser.add_argument("--landing-samples", type=int, default=LANDING_SAMPLES, choices=range(1, 41), metavar="K",
                        help=f"the first landing's times tried (1..40; default {LANDING_SAMPLES})")
    parser.add_argument("--json", action="store_true", help="one JSON object per push")
    parser.add_argument("--markdown", action="store_true", help="print the docs' figure (tools/figures.py)")
    args = parser.parse_args(argv)
    if not 1 <= args.pushes <= 10000:
        parser.error(f"--pushes: 1 to 10000, got {args.pushes}")
    if not (math.isfinite(args.max_impulse) and 0 < args.max_impulse <= 20):
        parser.error(f"--max-impulse: above 0 and at most 20 N s, got {args.max_impulse:g}")
    # the analysis's two search sizes, for a reader checking they do not matter
    module = sys.modules[__name__]
    module.MAX_STEPS, module.LANDING_SAMPLES = args.max_steps, args.landing_samples
    rows = table_rows(args)
    menagerie = menagerie_rows(args.robot)
    if args.markdown:
        print(markdown(args, rows, menagerie))
        return 0
    if args.json:
        for row in [*rows, *menagerie]:
            print(json.dumps(row))
        return 0
    print("| push | impulse N s | direction deg | phase | (a) step limits | (a) and the hips | (b) legs' reach |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['push']} | {r['impulse_n_s']:.2f} | {r['direction_deg']:.0f} | {r['phase']:.2f} | "
              f"{_cell(r['a'])} | {_cell(r['a_hip'])} | {_cell(r['b'])} |")
    count = {k: sum(r[k]["capturable"] for r in rows) for k in ("a", "a_hip", "b", "b_hip")}
    print(f"\n{args.robot}, {args.pushes} pushes of 0..{args.max_impulse:g} N s (seed {args.seed}): capturable "
          f"{count['a']} under the step limits ({count['a_hip']} with the hips), {count['b']} within the legs' "
          f"reach ({count['b_hip']} with the hips)")
    for m in menagerie:
        print(f"Menagerie's OP3 ({m['mass_kg']:g} kg, {MENAGERIE_WALK}), {m['impulse_n_s']:g} N s at "
              f"{m['direction_deg']:g} deg at {m['start_s']:g} s: (a) {_cell(m['a'])}; (a) and the hips "
              f"{_cell(m['a_hip'])}; (b) {_cell(m['b'])}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
