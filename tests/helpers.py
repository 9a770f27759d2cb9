"""Helpers shared by the check tests (no tests here; named test_check_* to stay in the check room):
run the real CLI, make dry-run recordings, and edit recordings packet by packet (re-framed with a
valid checksum/CRC unless the test wants it broken)."""
from __future__ import annotations

import json
from pathlib import Path

from gaitbot.servos import wire
from gaitbot.app.cli import main
from gaitbot.robot.config import load_robot_config, resolve_config

ROBOTS = ("xl430-biped", "sts3215-biped", "ax12a-biped")
PERIOD_S = 1.0 / 60.0


def run_cli(capsys, *argv) -> tuple[int, str, str]:
    """gaitbot.app.cli.main with ``argv``: (exit status, stdout, stderr)."""
    capsys.readouterr()
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def config(robot: str):
    return load_robot_config(resolve_config(robot))


def read_lines(path: Path) -> list[dict]:
    return [json.loads(line) for line in Path(path).read_text().splitlines()]


def write_lines(path: Path, rows: list[dict]) -> Path:
    Path(path).write_text("".join(json.dumps(r, separators=(",", ":")) + "\n" for r in rows))
    return Path(path)


def framing(header: dict) -> str:
    return "v2" if header["backend"] == "dynamixel" and float(header["protocol"]) == 2.0 else "v1"


def goal_layout(robot: str) -> tuple[int, int]:
    model = config(robot).joints[0].model
    return model.addr_goal_position, model.len_goal_position


def split_sync_write(header: dict, raw: bytes) -> tuple[int, int, list[tuple[int, bytes]]] | None:
    """(address, length, [(id, data)]) of a sync write packet, else None. Written from the
    protocol pages: v1 FF FF ID LEN INST P.. CK; v2 FF FF FD 00 ID LEN_L LEN_H INST P.. CRC_L CRC_H."""
    if framing(header) == "v2":
        if raw[7] != 0x83:
            return None
        params, step = raw[8:-2], 2  # no FF FF FD inside these payloads in the tests' recordings
        address, length = params[0] | params[1] << 8, params[2] | params[3] << 8
    else:
        if raw[4] != 0x83:
            return None
        params, step = raw[5:-1], 1
        address, length = params[0], params[1]
    body = params[2 * step:]
    entries = [(body[o], bytes(body[o + 1:o + 1 + length])) for o in range(0, len(body), length + 1)]
    return address, length, entries


def build_sync_write(header: dict, address: int, length: int, entries: list[tuple[int, bytes]]) -> bytes:
    body = b"".join(bytes([i]) + data for i, data in entries)
    if framing(header) == "v2":
        params = bytes([address & 0xFF, address >> 8, length & 0xFF, length >> 8]) + body
        return wire.build_v2(0xFE, 0x83, params)
    return wire.build_v1(0xFE, 0x83, bytes([address, length]) + body)


def goal_line_indices(rows: list[dict], robot: str) -> list[int]:
    """Indices into ``rows`` (0 = header) of the goal-position sync writes."""
    header = rows[0]
    layout = goal_layout(robot)
    out = []
    for k, row in enumerate(rows[1:], start=1):
        if row["dir"] != "tx":
            continue
        parts = split_sync_write(header, bytes.fromhex(row["hex"]))
        if parts is not None and parts[:2] == layout:
            out.append(k)
    return out


def goal_row_near(rows: list[dict], robot: str, t_s: float) -> int:
    """Index of the goal sync write whose time is closest to ``t_s``."""
    return min(goal_line_indices(rows, robot), key=lambda k: abs(rows[k]["t"] - t_s))
