"""A robot config's ``[steer]`` table: its steering limits (gaitbot.gait.steer.limits.SteerLimits).

Optional: a robot without it walks straight only (``--velocity`` and ``--commands`` say so). Every key
is required when the table is there, each inside SteerLimits' range; docs/robot-config.md lists them and
config/op3.toml and config/bioloid.toml say how their values were derived.
"""

from __future__ import annotations

from gaitbot.gait.steer.limits import RANGES, SteerLimits

STEER_UNITS = {"max_forward_m": "m", "max_backward_m": "m", "max_side_m": "m", "max_turn_deg": "deg",
               "min_gap_m": "m", "max_change_forward_m": "m", "max_change_side_m": "m", "max_change_turn_deg": "deg"}


def read_steer(reader, data: dict) -> SteerLimits | None:
    """The ``[steer]`` table read through the config's field reader (gaitbot.fields.Fields), or None."""
    if "steer" not in data:
        return None
    table = reader.table(data, "steer", "steer", SteerLimits.field_names())
    values = {key: reader.number(table, key, "steer", within=(*RANGES[key], STEER_UNITS[key]))
              for key in SteerLimits.field_names()}
    return SteerLimits(**values)
