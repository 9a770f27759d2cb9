"""``gaitbot plot``: a trajectory (or an eigen-gait model) drawn to a picture (gaitbot.plot)."""

from __future__ import annotations

from pathlib import Path

from gaitbot.app.options import UsageError, gait_source, walked_by
from gaitbot.gait.eigen import is_model_file
from gaitbot.gait.terrain.course_file import load_course
from gaitbot.gait.trajectory import Trajectory


def run(args) -> int:
    try:
        import matplotlib  # noqa: F401  (only plotting needs it: the `plot` extra)
    except ImportError:
        raise UsageError("plotting needs matplotlib: pip install 'gaitbot[plot]'") from None
    from gaitbot.plot import plot_eigen_model, plot_trajectory

    if Path(args.file).suffix == ".npz" and is_model_file(args.file):
        plot_eigen_model(args.file, Path(args.output))
        print(f"wrote {args.output}")
        return 0
    trajectory = Trajectory.load(args.file)
    source = gait_source(args)
    out = Path(args.output)
    terrain = None
    if getattr(args, "terrain", None) is not None:
        terrain = load_course(args.terrain).terrain
    plot_trajectory(trajectory, source.geometry, out, clearance=source.settings.clearance, title=Path(args.file).name,
                    terrain=terrain)
    print(f"wrote {out} (the feet drawn for {walked_by(source)})")
    return 0
