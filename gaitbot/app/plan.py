"""``gaitbot plan``: the step plan (lengths, RV, timing, footholds), as a table or one JSON object."""

from __future__ import annotations

import json
import math

from gaitbot.app.arguments import add_command, check_walk_source, walk_options
from gaitbot.app.options import walked_by
from gaitbot.app.planned_walk import planned_walk
from gaitbot.app.steer_options import steer_requested
from gaitbot.gait.walker import OnlineWalker
from gaitbot.robot.walk_settings import GaitSource


def add_parser(subparsers):
    p = add_command(subparsers, "plan")
    walk_options(p)
    p.add_argument("--json", action="store_true", help="print the plan as one JSON object")
    return p


def check_arguments(parser, args) -> None:
    check_walk_source(parser, args)


def run(args) -> int:
    walk = planned_walk(args)
    walk.say_notes()
    if getattr(args, "terrain", None) is not None:
        return _plan_terrain(args, walk)
    source = walk.source
    if steer_requested(args):
        from gaitbot.app.steer_walk import print_steered_plan, steered_plan_summary

        summary = steered_plan_summary(source, walk.plan)
        print(json.dumps(summary, indent=2)) if args.json else print_steered_plan(summary)
        return 0
    plan = balanced_plan_summary(source, walk.plan) if source.balanced else plan_summary(source, walk.plan)
    if args.json:
        print(json.dumps(plan, indent=2))
        return 0
    print(f"{'step':>4} {'leg':>5} {'length m':>9} {'RV':>7} {'start s':>8} {'end s':>7} {'foothold m':>10}")
    for s in plan["steps"] + ([plan["closing_step"]] if plan["closing_step"] else []):
        label = "close" if s["closing"] else str(s["index"])
        rv = f"{s['rv']:7.4f}" if s["rv"] is not None else f"{'-':>7}"
        print(f"{label:>4} {s['leg']:>5} {s['length_m']:9.4f} {rv} {s['start_s']:8.3f} {s['end_s']:7.3f} "
              f"{s['foothold_m']:10.4f}")
    print(f"{walked_by(source)}: {plan['n_steps']} steps, {plan['total_distance_m']:.4f} m in {plan['duration_s']:.2f} s "
          f"(cycle {plan['cycle_s']:.4f} s, {plan['rate_hz']:g} Hz, reachable step 0 to "
          f"{plan['reachable_step_m'][1]:.4f} m, allowed up to {plan['max_step_m']:.4f} m). "
          f"RV: walking speed over leg length, which sets Boulic's joint motion (docs/gait-model.md)")
    return 0


def _plan_terrain(args, walk) -> int:
    source = walk.source
    plan = terrain_plan_summary(source, walk.plan)
    if args.json:
        print(json.dumps(plan, indent=2))
        return 0
    print(f"{'step':>4} {'leg':>5} {'length m':>9} {'start s':>8} {'end s':>7} {'foothold m':>10} {'height m':>8} "
          f"{'method':>8} {'lift m':>7}")
    for s in plan["steps"]:
        label = "close" if s["closing"] else str(s["index"])
        print(f"{label:>4} {s['leg']:>5} {s['length_m']:9.4f} {s['start_s']:8.3f} {s['end_s']:7.3f} "
              f"{s['foothold_m']:10.4f} {s['height_m']:8.4f} {s['method']:>8} {s['lift_m']:7.4f}")
    if plan["searches"]:
        print("Pelvis low points between steps (mid double support, MDS), each chosen by Zhang's grid search "
              "for the least joint acceleration (cost: weighted squared joint accelerations, (rad/s^2)^2 s):")
    for i, r in enumerate(plan["searches"], start=1):
        centre = f"{r['centre_cost']:.4g}" if r["centre_cost"] is not None else "out of the legs' reach"
        print(f"{i:4d}: pelvis at ({r['mds_m'][0]:.4f}, {r['mds_m'][1]:.4f}) m, cost {r['cost']:.4g} "
              f"(the middle of the region: {centre}); {r['evaluated']} cells scored, {r['pruned']} skipped as "
              f"unreachable, of {r['full_grid']} in a full search")
    print(f"{walked_by(source)}: {plan['n_steps']} steps ({plan['n_terrain_steps']} by the terrain walker, the others by the flat "
          f"walker), {plan['duration_s']:.2f} s, {plan['n_frames']} frames; the grid searches scored "
          f"{plan['cells_evaluated']} cells against {plan['cells_full_search']} for full searches. lift: how high "
          f"the swing foot is lifted above its path")
    return 0


def balanced_plan_summary(source: GaitSource, plan) -> dict:
    """A balanced walk's plan as a JSON-ready object: the same keys as plan_summary (RV is None: the
    balanced walker has no Boulic RV), with the heel strikes' y and the settings it walks with."""
    walk, fit = plan.walk, plan.fit
    steps = [s.to_dict() for s in walk.planned_steps if not s.closing]
    closing = [s.to_dict() for s in walk.planned_steps if s.closing]
    timing = plan.walker.timing
    return {
        "robot": source.robot.name,
        "walker": "balanced",
        "leg_length_m": source.geometry.leg_length,
        "cycle_s": timing.cycle_s,
        "rate_hz": timing.rate_hz,
        "reachable_step_m": [0.0, source.max_step_m],
        "max_step_m": fit.gait.max_step_m,
        "steps": steps,
        "closing_step": closing[0] if closing else None,
        "heel_strikes": [{"t_s": h.t_s, "leg": h.leg, "x_m": h.x_m, "y_m": h.y_m} for h in walk.heel_strikes],
        "total_distance_m": walk.heel_strikes[-1].x_m if walk.heel_strikes else 0.0,
        "n_steps": len(steps),
        "duration_s": float(walk.t_s[-1]),
        "n_frames": len(walk.t_s),
        "crouch_knee_deg": fit.balance.crouch_knee_deg,
        "double_support_share": fit.balance.double_support_share,
        "progression_end": fit.balance.progression_end,
        "clearance_m": fit.gait.clearance_m,
        "peak_joint_speed_dps": fit.peak_dps,
        "sag_feedforward": plan.walker.feedforward,
        "com_height_m": plan.walker.com_height_m,
        "preview_horizon_s": plan.walker.gains.horizon_frames / timing.rate_hz,
    }


def plan_summary(source: GaitSource, walker: OnlineWalker) -> dict:
    """The plan as a JSON-ready object: requested steps, the closing step, footholds and totals."""
    steps = [s.to_dict() for s in walker.planned_steps if not s.closing]
    closing = [s.to_dict() for s in walker.planned_steps if s.closing]
    n_frames = walker._planned_frames
    return {
        "robot": source.robot.name if source.robot is not None else None,
        "leg_length_m": source.geometry.leg_length,
        "cycle_s": walker.ctx.cycle_s,
        "rate_hz": walker.ctx.rate_hz,
        "reachable_step_m": list(walker.ctx.inverse.reachable_range),
        "max_step_m": source.max_step_m,
        "steps": steps,
        "closing_step": closing[0] if closing else None,
        "heel_strikes": [{"t_s": h.t_s, "leg": h.leg, "x_m": h.x_m} for h in walker.heel_strikes],
        "total_distance_m": walker.heel_strikes[-1].x_m if walker.heel_strikes else 0.0,
        "n_steps": len(steps),
        "duration_s": (n_frames - 1) / walker.ctx.rate_hz,
        "n_frames": n_frames,
    }


def terrain_plan_summary(source: GaitSource, walk) -> dict:
    """A terrain plan as a JSON-ready object: steps with their method, footholds, and the grid searches."""
    searches = [{"mds_m": list(r.point), "cost": r.cost, "centre_cost": r.centre_cost if math.isfinite(r.centre_cost)
                 else None, "evaluated": r.evaluated, "pruned": r.pruned, "full_grid": r.full_grid}
                for r in walk.search_reports]
    traj = walk.trajectory
    return {
        "robot": source.robot.name if source.robot is not None else None,
        "leg_length_m": source.geometry.leg_length,
        "rate_hz": walk.ctx.rate_hz,
        "steps": [s.to_dict() for s in walk.steps],
        "n_steps": len(walk.steps),
        "n_terrain_steps": sum(1 for s in walk.steps if s.method == "terrain"),
        "searches": searches,
        "cells_evaluated": sum(r.evaluated for r in walk.search_reports),
        "cells_full_search": sum(r.full_grid for r in walk.search_reports),
        "duration_s": float(traj.t_s[-1]),
        "n_frames": len(traj),
        "total_distance_m": walk.steps[-1].foothold_m - (walk.steps[0].foothold_m - walk.steps[0].length_m),
    }
