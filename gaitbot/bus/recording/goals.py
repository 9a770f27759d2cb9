"""The goal frames of a bus recording: what a walk asked its servos to do, frame by frame."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gaitbot.bus.recording.reader import RecordingError, parse_recording, typed_header
from gaitbot.servos import wire
from gaitbot.servos.models import servo_model


def decode_goal_frames(path: str | Path, *, allow_partial_last_line: bool = False
                       ) -> tuple[dict, np.ndarray, np.ndarray]:
    """(header, t_s (N,), ticks (N, n_joints)) from the goal-position sync writes of a log.

    Columns follow the header's joint order. Every tx packet must pass its checksum/CRC. A joint
    missing from a frame is NaN in that row (ticks is float64 so it can say so).
    """
    header, parsed = parse_recording(path, allow_partial_last_line=allow_partial_last_line)
    goal = _goal_layout(path, header)
    joint_ids = list(header["joints"].values())
    column = {servo_id: c for c, servo_id in enumerate(joint_ids)}
    times, rows = [], []
    for p in parsed:
        if p.direction != "tx":
            continue
        if not p.checksum_ok:
            raise RecordingError(f"{path}:{p.line_no}: tx packet rejected: {p.problem}")
        if p.instruction != wire.INST_SYNC_WRITE or (p.address, p.data_length) != goal[0]:
            continue
        row = np.full(len(joint_ids), np.nan)
        for servo_id, raw in p.per_id_data.items():
            if servo_id in column:
                row[column[servo_id]] = int.from_bytes(raw, goal[1][servo_id])
        times.append(p.t_s)
        rows.append(row)
    ticks = np.array(rows, dtype=float).reshape(len(rows), len(joint_ids))
    return header, np.array(times, dtype=float), ticks


def _goal_layout(path: Path, header: dict) -> tuple[tuple[int, int], dict[int, str]]:
    """((goal address, length), {id: byte order}) from the header's models."""
    models = {i: servo_model(name) for i, name in typed_header(header)["models"].items()}
    layouts = {(m.addr_goal_position, m.len_goal_position) for m in models.values()}
    if len(layouts) != 1:
        raise RecordingError(f"{path}:1: header models do not share one goal-position address")
    return layouts.pop(), {i: m.byte_order for i, m in models.items()}
