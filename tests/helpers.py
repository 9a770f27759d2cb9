"""Helpers shared by the tests (no tests here; conftest.py puts this folder on the path).

The repository's folders; the real CLI run in-process; recordings edited packet by packet
(re-framed with a valid checksum/CRC unless the test wants it broken); a packet decoder written
from the protocol documents, independently of gaitbot's; the tests' own terrain profile; the
simulated robot floated in the air.
"""
from __future__ import annotations

import io
import json
import os
import re
import resource
import signal
import subprocess
import sys
import tempfile
import time
import traceback
from pathlib import Path

import numpy as np
import pytest

from gaitbot.app.cli import main
from gaitbot.check.trajectory import check_trajectory
from gaitbot.errors import UserError
from gaitbot.robot.calibration import ticks_to_angles
from gaitbot.robot.config import load_robot_config, resolve_config
from gaitbot.servos import wire

REPO_ROOT = Path(__file__).resolve().parents[1]
CONFIG_DIR = REPO_ROOT / "config"
WALK_TIMEOUT_S = 60  # a hang fails the test instead of the suite


def slow_except(values, *quick):
    """A parametrize list whose cases all go to the slow set except those in ``quick``: the quick loop keeps
    one representative of a behaviour, the full run (and CI) every robot, protocol and fault. A case is kept
    quick when it, its first argument (a tuple is a case of several arguments) or its ``pytest.param`` id is
    a name in ``quick``; a ``pytest.param`` keeps its id and marks."""
    cases = []
    for value in values:
        is_param = isinstance(value, type(pytest.param(None)))
        args = value.values if is_param else value if isinstance(value, tuple) else (value,)
        names = {v for v in (value, args[0], value.id if is_param else None) if isinstance(v, str)}
        if names & set(quick):
            cases.append(value)
        else:
            marks = [*value.marks, pytest.mark.slow] if is_param else [pytest.mark.slow]
            cases.append(pytest.param(*args, id=value.id if is_param else None, marks=marks))
    return cases


# --- the command line and the emulator


def gaitbot(*args: str, timeout: float = WALK_TIMEOUT_S) -> subprocess.CompletedProcess:
    """The gaitbot command line in a subprocess, as a user runs it."""
    return subprocess.run([sys.executable, "-m", "gaitbot.app.cli", *args], capture_output=True, text=True,
                          timeout=timeout, stdin=subprocess.DEVNULL, cwd=REPO_ROOT)


def emulator_for(config_path: Path, log_path: Path, faults=None, model_numbers=None, imu=None):
    """The servo emulator (gaitbot.emulator) of a robot config on a pty, logging the goals it receives;
    ``model_numbers`` (servo id -> number): servos that report another model number than their model's;
    ``imu``: an IMU device on the line (gaitbot.bus.imu_device.ImuDevice)."""
    import gaitbot.emulator as se

    robot = load_robot_config(config_path)
    return se.ServoEmulator(se.EmulatorConfig(
        robot.bus.backend, robot.bus.protocol, robot.models_by_id, robot.bus.baudrate, faults or se.Faults(),
        str(log_path), robot.name, {j.name: j.id for j in robot.joints}, model_numbers=dict(model_numbers or {}),
        imu=imu))


def grid_limit_errors(config, ticks: np.ndarray, from_frame: int) -> list[str]:
    """Joint limits of the goal frames from ``from_frame - 2`` on, one period apart (the session's grid)."""
    start = max(0, from_frame - 2)
    angles = np.degrees(ticks_to_angles(config, ticks[start:]))
    t = np.arange(len(angles)) / config.gait.rate_hz
    report = check_trajectory(config, t, angles)
    # one tick of rounding in each frame is what no integer goal can avoid
    slack = {"velocity": config.gait.rate_hz, "acceleration": 2 * config.gait.rate_hz ** 2}
    errors = []
    for v in report.errors:
        joint = next(j for j in config.joints if j.name == v.joint)
        tick_deg = 360.0 / (2 * np.pi * joint.model.ticks_per_rad)
        if v.kind in slack and abs(v.value) <= v.limit + slack[v.kind] * tick_deg + 1e-9:
            continue
        errors.append(v.describe())
    return errors


# --- recordings

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


def recorded_goal_ticks(record: Path, robot: str, joints) -> list[list[int]]:
    """Each goal-position sync write of a bus recording as ticks in the order of ``joints`` (config joints)."""
    rows = read_lines(record)
    sent = []
    for k in goal_line_indices(rows, robot):
        _, _, entries = split_sync_write(rows[0], bytes.fromhex(rows[k]["hex"]))
        ticks = dict((i, int.from_bytes(d, "little")) for i, d in entries)
        sent.append([ticks[j.id] for j in joints])
    return sent


def goal_row_near(rows: list[dict], robot: str, t_s: float) -> int:
    """Index of the goal sync write whose time is closest to ``t_s``."""
    return min(goal_line_indices(rows, robot), key=lambda k: abs(rows[k]["t"] - t_s))


# --- an independent packet decoder (ROBOTIS protocol 1.0 / Feetech checksum = ~(sum of id..params) & 0xFF;
# protocol 2.0 CRC-16 with polynomial 0x8005, initial value 0, no reflection: the e-Manual), bit by bit


def crc16(data: bytes) -> int:
    crc = 0
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x8005) if crc & 0x8000 else (crc << 1)
            crc &= 0xFFFF
    return crc


def parse_packet(raw: bytes, protocol: float):
    """(id, instruction, params) of one instruction packet; raises AssertionError if malformed."""
    if protocol == 2.0:
        assert raw[:4] == b"\xff\xff\xfd\x00", raw.hex()
        length = raw[5] | raw[6] << 8
        assert len(raw) == 7 + length, raw.hex()
        assert crc16(raw[:-2]) == (raw[-2] | raw[-1] << 8), f"bad CRC {raw.hex()}"
        body = raw[7:-2].replace(b"\xff\xff\xfd\xfd", b"\xff\xff\xfd")  # unstuff
        return raw[4], body[0], body[1:]
    assert raw[:2] == b"\xff\xff", raw.hex()
    length = raw[3]
    assert len(raw) == 4 + length, raw.hex()
    assert (~sum(raw[2:-1])) & 0xFF == raw[-1], f"bad checksum {raw.hex()}"
    return raw[2], raw[4], raw[5:-1]


# --- the tests' own terrain profile, built from the treads independently of gaitbot's Terrain: ground at 0
# outside the treads, neighbouring pieces of equal height merged into one surface


def surface_pieces(treads):
    """[start, end, height] pieces covering the whole x axis, in order."""
    pieces, x = [], -np.inf
    for t in sorted(treads, key=lambda t: t.start_m):
        if t.start_m > x + 1e-9:
            pieces.append([x, t.start_m, 0.0])
        pieces.append([t.start_m, t.start_m + t.length_m, t.height_m])
        x = t.start_m + t.length_m
    pieces.append([x, np.inf, 0.0])
    merged = []
    for p in pieces:
        if merged and merged[-1][2] == p[2] and abs(merged[-1][1] - p[0]) < 1e-9:
            merged[-1][1] = p[1]
        else:
            merged.append(p)
    return merged


def height(pieces, x):
    """Terrain height under each x (at an edge: the higher side)."""
    out = np.zeros_like(x)
    for i, xi in enumerate(x):
        out[i] = max(h for s, e, h in pieces if s - 1e-12 <= xi <= e + 1e-12)
    return out


def heights_under(pieces, x):
    """``height`` for an array of any shape, vectorised (at an edge: the higher side)."""
    x = np.asarray(x, dtype=float)
    out = np.full(x.shape, -np.inf)
    for start, end, h in pieces:
        out = np.where((x >= start - 1e-12) & (x <= end + 1e-12), np.maximum(out, h), out)
    return out


def fk_foot(cfg, q, root_xz):
    """Ankle, heel and toe in the sagittal plane (x forward, z up) of one leg from hip, knee, ankle flexion
    (the tests' own kinematics, docs/gait-model.md section 1; the heel is heel_back_m behind the ankle's
    projection on the sole). ``root_xz`` is the root's (x, z): a trajectory's ``root_xz_m``, not its 3D ``root_m``."""
    g = cfg.geometry
    root_xz = np.asarray(root_xz)
    assert root_xz.shape == (len(q), 2), f"fk_foot takes the root's (x, z), got shape {root_xz.shape}"
    h, k, a = q[:, 0], q[:, 1], q[:, 2]
    ankle = root_xz + np.column_stack([g.thigh_m * np.sin(h) + g.shank_m * np.sin(h - k),
                                    -g.thigh_m * np.cos(h) - g.shank_m * np.cos(h - k)])
    p = h - k + a  # sole pitch, toe up
    along_sole = np.column_stack([np.cos(p), np.sin(p)])
    heel = ankle + g.ankle_height_m * np.column_stack([np.sin(p), -np.cos(p)]) - g.heel_back_m * along_sole
    return ankle, heel, heel + g.foot_m * along_sole


def swing_clearances(cfg, trajectory, treads=()) -> list[tuple[float, float, float]]:
    """Per swing of either foot, by the tests' own kinematics and docs/gait.md's rule: (forward travel m, least
    height of the whole sole above the ground under it while the ankle covers 10% to 90% of its forward travel,
    share of the swing's time before the sole is 0.2 mm off the ground). A swing runs between two frames in
    which the foot's lowest point is on the ground (within 0.01 mm)."""
    pieces = surface_pieces(treads)
    out = []
    for side in (0, 1):
        ankle, heel, toe = fk_foot(cfg, trajectory.angles_rad[:, 3 * side:3 * side + 3], trajectory.root_xz_m)
        u = np.linspace(0.0, 1.0, 21)
        sole = heel[:, None, :] + u[None, :, None] * (toe - heel)[:, None, :]
        gap = (sole[..., 1] - heights_under(pieces, sole[..., 0])).min(axis=1)
        down = np.flatnonzero(gap <= 1e-5)
        for a, b in zip(down[:-1], down[1:]):
            if b - a < 2:
                continue
            travel = ankle[b, 0] - ankle[a, 0]
            if travel < 1e-3:
                continue  # a foot set down where it was lifted (a step of 0) does not move forward
            progress = (ankle[a:b + 1, 0] - ankle[a, 0]) / travel
            moving = (progress >= 0.1) & (progress <= 0.9)
            up = int(np.argmax(gap[a:b + 1] > 2e-4))
            out.append((travel, gap[a:b + 1][moving].min(), (trajectory.t_s[a + up] - trajectory.t_s[a])
                        / (trajectory.t_s[b] - trajectory.t_s[a])))
    return out


# --- the simulated robot (gaitbot.sim.physics.SimRobot)


def float_in_air(robot) -> None:
    """Lift the robot off the floor and switch gravity off: only the servos act on the legs."""
    robot.model.opt.gravity[:] = 0.0
    robot.data.qpos[robot.model.joint("boom_z").qposadr[0]] = 0.5
    robot.mujoco.mj_forward(robot.model, robot.data)


# --- bounded runs of hostile input (tests/test_hostile_input.py, tests/app/test_hostile_cases.py)

TIME_BOUND_S = 20.0
MEMORY_HEADROOM = 1536 * 2**20  # bytes of address space a child may add to what the test process has mapped
PY_WARNING = re.compile(r"\w*Warning\b")


def _child(fn, args, write_fd: int, capture: bool) -> None:
    result: dict
    try:
        with open("/proc/self/status") as f:
            vm = next(int(line.split()[1]) * 1024 for line in f if line.startswith("VmSize:"))
        resource.setrlimit(resource.RLIMIT_AS, (vm + MEMORY_HEADROOM, vm + MEMORY_HEADROOM))
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        if capture:
            out, err = tempfile.TemporaryFile(), tempfile.TemporaryFile()
            os.dup2(out.fileno(), 1)
            os.dup2(err.fileno(), 2)
            sys.stdout = io.TextIOWrapper(os.fdopen(os.dup(1), "wb"), encoding="utf-8", line_buffering=True)
            sys.stderr = io.TextIOWrapper(os.fdopen(os.dup(2), "wb"), encoding="utf-8", line_buffering=True)
        start = time.monotonic()
        try:
            value = fn(*args)
            result = {"outcome": "ok", "value": value if isinstance(value, (int, type(None))) else None}
        except SystemExit as exc:
            result = {"outcome": "ok", "value": exc.code if isinstance(exc.code, int) else 1}
        except BaseException as exc:  # noqa: BLE001 - everything is reported
            result = {"outcome": "raised", "type": type(exc).__name__, "user_error": isinstance(exc, UserError),
                      "message": str(exc)[:2000], "traceback": traceback.format_exc()[-2000:]}
        result["elapsed_s"] = time.monotonic() - start
        if capture:
            sys.stdout.flush()
            sys.stderr.flush()
            out.seek(0)
            err.seek(0)
            result["stdout"] = out.read().decode("utf-8", "replace")[-50000:]
            result["stderr"] = err.read().decode("utf-8", "replace")[-50000:]
    except BaseException as exc:  # noqa: BLE001
        result = {"outcome": "raised", "type": type(exc).__name__, "user_error": False, "message": f"(harness) {exc}"}
    with os.fdopen(write_fd, "wb") as pipe:
        pipe.write(json.dumps(result, default=str).encode())
    os._exit(0)


def isolated(fn, *args, capture: bool = False, bound_s: float = TIME_BOUND_S) -> dict:
    """``fn(*args)`` in a forked child with a memory limit and a time bound: what happened, as a dict."""
    read_fd, write_fd = os.pipe()
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:
        os.close(read_fd)
        try:
            _child(fn, args, write_fd, capture)
        finally:
            os._exit(70)
    os.close(write_fd)
    os.set_blocking(read_fd, False)
    chunks, start = [], time.monotonic()
    while True:
        try:
            chunk = os.read(read_fd, 1 << 16)
            if chunk:
                chunks.append(chunk)
        except BlockingIOError:
            pass
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            break
        if time.monotonic() - start > bound_s:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            os.close(read_fd)
            return {"outcome": "timeout", "elapsed_s": time.monotonic() - start}
        time.sleep(0.002)
    try:
        while chunk := os.read(read_fd, 1 << 16):
            chunks.append(chunk)
    except BlockingIOError:
        pass
    os.close(read_fd)
    if not chunks:
        return {"outcome": "crash", "status": status}
    return json.loads(b"".join(chunks))


def assert_reader_behaves(result: dict, path: Path) -> None:
    """Accepted, or one UserError naming the file; nothing else, within the bounds."""
    assert result["outcome"] in ("ok", "raised"), result
    if result["outcome"] == "raised":
        assert result["user_error"], f"{result['type']}: {result['message']}\n{result.get('traceback', '')}"
        assert path.name in result["message"], result["message"]
        assert "\n" not in result["message"].strip() or result["type"] == "ConfigError", result["message"]


def assert_cli_behaves(result: dict, allowed=(0, 2)) -> None:
    """Exit 0/2 (or as allowed), never a traceback or a warning, and an error is one line."""
    assert result["outcome"] == "ok", result
    code, err = result["value"], result["stderr"]
    assert "Traceback" not in err, err
    assert not PY_WARNING.search(err), err
    assert code in allowed, (code, err, result["stdout"][-500:])
    if code == 2:
        lines = [line for line in err.splitlines() if line.strip()]
        assert len(lines) == 1 and lines[0].startswith("gaitbot"), err
        assert not result["stdout"].strip(), result["stdout"]


def cli(*argv: str) -> dict:
    return isolated(main, [str(a) for a in argv], capture=True)




def knee_calibration(zero_tick: int, direction: int = 1) -> str:
    """A calibration file's text for xl430-biped that moves only knee_pitch_left (servo 2)."""
    return f"""[calibration]
format = "gaitbot-calibration"
version = 1
robot = "xl430-biped"

[joints.knee_pitch_left]
id = 2
model = "XL430-W250"
zero_tick = {zero_tick}
direction = {direction}
"""


class Felt:
    """A tilt estimate that reports what it is given (what the stepping source reads of a TiltEstimate)."""

    def __init__(self, roll_deg=0.0, pitch_deg=0.0, rates=(0.0, 0.0, 0.0), started=True):
        import numpy as np

        self.roll_deg, self.pitch_deg, self.rates_dps, self.started = roll_deg, pitch_deg, np.array(rates), started


def op3_stepping_plan():
    """The op3's balanced plan of six 6 cm steps at the 0.8 s cycle (the pushed walk's steps): (config, plan)."""
    from gaitbot.robot.balanced_walk import balanced_gait_settings, plan_balanced

    cfg = config("op3")
    return cfg, plan_balanced(cfg, [0.06] * 6, balanced_gait_settings(cfg, cycle_s=0.8, max_step_m=0.06))
