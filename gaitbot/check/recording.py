"""Limit checking of a recorded bus run (a ``gaitbot-bus-log`` JSON Lines file, gaitbot.bus.recording).

A recording is checked in two layers: **the bus** (every packet well formed, every goal frame
addressing exactly the configured ids, no unknown ids, the regularity of the goal frames against the
configured rate: a gap over ``MAX_GAP_PERIODS`` periods left the servos without a new goal that long)
and **the joints** (the goal ticks decoded back to angles and put through the very same
``check_trajectory`` as a trajectory file, at the recorded send times).

Choices, written out in docs/checking.md: the robot is ``--robot`` or the shipped config the header
names, and must match the recording (else exit 2); all goal sync writes form one series (a session
keeps one deadline grid from its first goal on); a goal write at the same time as the one before
supersedes it; a corrupted goal write counts for timing but not for motion; a joint missing from a
frame keeps its goal; other WRITE packets are settings (gaitbot/check/settings.py). A malformed packet
is a fault of the run (exit 1); an unreadable file is exit 2.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from gaitbot.bus import recording
from gaitbot.bus.recording import BusLog, RecordingError, read_header, typed_header
from gaitbot.check.health import HealthReport, health_report
from gaitbot.check.settings import SettingWrite, describe_settings, setting_write
from gaitbot.check.trajectory import CheckReport, check_trajectory
from gaitbot.robot.calibration import ticks_to_angles
from gaitbot.robot.config import RobotConfig, shipped_config_dirs, shipped_config_names
from gaitbot.robot.health import health_thresholds
from gaitbot.servos import wire

MAX_GAP_PERIODS = 1.5
BUS_KIND_ORDER = ("packet", "ids", "timing", "status", "health", "file", "config")
_HEX_SHOWN = 48  # hex characters of a packet quoted in a message


class RecordingMismatch(RecordingError):
    """The robot config does not describe the robot the recording was made with (exit 2)."""


@dataclass(frozen=True)
class BusIssue:
    """A problem of the recorded bus traffic (not of a joint's motion).

    kind: "packet" (malformed), "ids" (missing/unknown/repeated id), "timing" (late frame, time
    backwards), "status" (a servo reported an error), "health" (a servo's temperature, voltage or load
    read past a threshold: gaitbot.check.health), "file" (partial last line), "config" (recording and
    config differ in a detail that does not change the checks).
    """

    kind: str
    severity: str  # "error" | "warning"
    line_no: int
    t_s: float
    message: str
    packet_hex: str = ""

    def describe(self) -> str:
        text = f"line {self.line_no}, t={self.t_s:.3f} s: {self.message}"
        if self.packet_hex:
            shown = self.packet_hex if len(self.packet_hex) <= _HEX_SHOWN else self.packet_hex[:_HEX_SHOWN] + "..."
            text += f" [{shown}]"
        return text


@dataclass(frozen=True)
class FrameTiming:
    """Regularity of the streamed goal writes against the configured rate."""

    rate_hz: float
    period_s: float
    n_frames: int
    mean_gap_s: float
    p99_gap_s: float
    worst_gap_s: float
    worst_gap_t_s: float  # time of the frame that ended the worst gap
    worst_gap_line: int
    max_gap_s: float  # the limit: MAX_GAP_PERIODS periods
    n_late: int
    n_backwards: int

    def describe(self) -> str:
        ms = 1000.0
        if self.n_frames < 2:
            return f"frame timing: {self.n_frames} streamed goal frame(s), no gaps to measure"
        return (f"frame timing over {self.n_frames} goal frames at {self.rate_hz:g} Hz "
                f"(period {self.period_s * ms:.2f} ms): mean gap {self.mean_gap_s * ms:.2f} ms, "
                f"p99 {self.p99_gap_s * ms:.2f} ms, worst {self.worst_gap_s * ms:.2f} ms "
                f"({self.worst_gap_s / self.period_s:.2f} periods) at t={self.worst_gap_t_s:.3f} s "
                f"(line {self.worst_gap_line}); limit {self.max_gap_s * ms:.2f} ms "
                f"({MAX_GAP_PERIODS:g} periods): {self.n_late} late, {self.n_backwards} backwards")


@dataclass(frozen=True)
class RecordingReport:
    """Result of ``check_recording``: bus issues, frame timing and the joint check of the goal frames."""

    path: str
    robot: str
    backend: str
    protocol: float
    n_packets: int
    n_tx: int
    n_rx: int
    n_goal_frames: int
    timing: FrameTiming
    issues: tuple[BusIssue, ...]
    joints: CheckReport
    sample_lines: tuple[int, ...]  # line of each motion sample, in order (for naming lines)
    sample_t_s: tuple[float, ...]
    settings: tuple[SettingWrite, ...] = ()  # gain (and other setting) writes, in file order
    settings_text: tuple[str, ...] = ()  # the same, one line per register and value, for people
    health: HealthReport | None = None  # the servo health reads of the run (gaitbot.check.health)
    health_text: tuple[str, ...] = ()  # its extremes, for people

    @property
    def errors(self) -> tuple[BusIssue, ...]:
        return tuple(i for i in self.issues if i.severity == "error")

    @property
    def warnings(self) -> tuple[BusIssue, ...]:
        return tuple(i for i in self.issues if i.severity == "warning")

    @property
    def ok(self) -> bool:
        return not self.errors and self.joints.ok

    @property
    def first_error(self) -> str | None:
        if self.errors:
            return self.errors[0].describe()
        return self.joints.first_error

    def line_of(self, t_s: float) -> int | None:
        """The recording line of the motion sample at ``t_s`` (None if there is none)."""
        times = np.asarray(self.sample_t_s)
        i = int(np.searchsorted(times, t_s))
        for j in (i, i - 1):
            if 0 <= j < len(times) and times[j] == t_s:
                return self.sample_lines[j]
        return None

    def to_dict(self) -> dict:
        joint_violations = self.joints.to_dict()
        for v in joint_violations["violations"]:
            v["line_no"] = self.line_of(v["t_s"])
        n_errors = len(self.errors) + len(self.joints.errors)
        n_warnings = len(self.warnings) + len(self.joints.warnings)
        return {
            "ok": self.ok,
            "kind": "recording",
            "file": self.path,
            "robot": self.robot,
            "backend": self.backend,
            "protocol": self.protocol,
            "n_packets": self.n_packets,
            "n_tx": self.n_tx,
            "n_rx": self.n_rx,
            "n_goal_frames": self.n_goal_frames,
            "n_errors": n_errors,
            "n_warnings": n_warnings,
            "first_error": self.first_error,
            "frame_timing": asdict(self.timing),
            "bus_issues": [{**asdict(i), "message_line": i.describe()} for i in self.issues],
            "settings": [asdict(w) for w in self.settings],
            "servo_health": self.health.to_dict() if self.health is not None else None,
            "joint_check": joint_violations,
        }

    def format_text(self, max_per_kind: int = 5) -> str:
        n_errors = len(self.errors) + len(self.joints.errors)
        n_warnings = len(self.warnings) + len(self.joints.warnings)
        lines = [f"{self.path}: recording of {self.robot} ({self.backend} protocol {self.protocol:g}): "
                 f"{'OK' if self.ok else 'FAIL'} ({n_errors} errors, {n_warnings} warnings)",
                 f"bus: {self.n_packets} packets ({self.n_tx} tx, {self.n_rx} rx), {self.n_goal_frames} goal frames; "
                 f"{_count(self.issues, 'packet')} malformed, {_count(self.issues, 'ids')} id problems, "
                 f"{_count(self.issues, 'timing')} timing problems",
                 self.timing.describe(),
                 *(f"settings written: {line}" for line in self.settings_text),
                 *self.health_text,
                 "",
                 "joint limits, goal ticks decoded to angles at the recorded send times:",
                 self.joints.format_text(max_per_kind)]
        lines = _with_lines(lines, self)
        for kind in BUS_KIND_ORDER:
            found = [i for i in self.issues if i.kind == kind]
            if not found:
                continue
            if kind == "health":  # a stop threshold reached matters more than the warnings before it
                found.sort(key=lambda i: (i.severity != "error", i.line_no))
            lines += ["", f"{kind} ({len(found)}):"]
            lines += [f"  {i.severity}: {i.describe()}" for i in found[:max_per_kind]]
            if len(found) > max_per_kind:
                lines.append(f"  ... and {len(found) - max_per_kind} more")
        return "\n".join(lines)


def _count(issues, kind: str) -> int:
    return sum(1 for i in issues if i.kind == kind)


def _with_lines(lines: list[str], report: RecordingReport) -> list[str]:
    """Append the recording line to each joint violation printed by the trajectory report."""
    by_message = {}
    for v in report.joints.violations:
        line = report.line_of(v.t_s)
        if line is not None:
            by_message[v.describe()] = line
    text = "\n".join(lines)
    out = []
    for row in text.split("\n"):
        stripped = row.strip()
        for prefix in ("error: ", "warning: "):
            if stripped.startswith(prefix) and stripped[len(prefix):] in by_message:
                row += f" (line {by_message[stripped[len(prefix):]]})"
                break
        out.append(row)
    return out


# ---------------------------------------------------------------------------------------------- reading


@dataclass(frozen=True)
class _Logged:
    """One packet line: parsed packet or, when its hex is not hex, the problem."""

    line_no: int
    t_s: float
    direction: str
    hex: str
    parsed: object | None  # ParsedPacket
    problem: str


def read_log(path: str | Path, *, allow_partial_last_line: bool = False) -> tuple[dict, list[_Logged], list[BusIssue]]:
    """A recording read by its format's reader (gaitbot.bus.recording), as the checks take it: the typed header,
    every packet line parsed, and file-level warnings. RecordingError (exit 2) for an unreadable file."""
    log = recording.read_log(path, allow_partial_last_line=allow_partial_last_line)
    packets, notes = _packets(log)
    return typed_header(log.header), packets, notes


def _packets(log: BusLog) -> tuple[list[_Logged], list[BusIssue]]:
    """Every packet line of a log (gaitbot.bus.recording, the format's reader) parsed, and file-level warnings."""
    packets = []
    for line in log.lines:
        if line.data is None:
            packets.append(_Logged(line.line_no, line.t_s, line.direction, line.hex, None, line.problem))
            continue
        parsed = line.packet
        packets.append(_Logged(line.line_no, line.t_s, line.direction, line.hex, parsed,
                               "" if parsed.checksum_ok else parsed.problem))
    notes = []
    if log.dropped_partial_line is not None:
        notes.append(BusIssue("file", "warning", log.dropped_partial_line, packets[-1].t_s if packets else 0.0,
                              "truncated last line (no newline) ignored; checked the complete lines before it"))
    return packets, notes


# ---------------------------------------------------------------------------------------------- robot


def robot_for_recording(path: str | Path, robot: str | None, load_robot) -> RobotConfig:
    """The config to check ``path`` against: ``robot`` if given, else the shipped config named in the
    header. ``load_robot`` is ``gaitbot.app.options.load_robot`` (passed in: the check room does not
    import the command line)."""
    if robot:
        return load_robot(robot)
    header = read_header(path)
    name = str(header.get("robot", ""))
    if name in shipped_config_names():
        for directory in shipped_config_dirs():
            candidate = directory / f"{name}.toml"
            if candidate.is_file():
                return load_robot(str(candidate))
    raise RecordingError(f"{path}: recorded with robot {name!r}, which is not a shipped config "
                         f"({', '.join(shipped_config_names())}); give its config with --robot PATH")


def match_config(path: str | Path, header: dict, config: RobotConfig) -> list[BusIssue]:
    """Raise RecordingMismatch when ``config`` is not the robot of the recording; return warnings
    for differences that do not change the checks."""
    rec_joints = header["joints"]
    cfg_joints = {j.name: j.id for j in config.joints}
    where = f"{path}: recording does not match robot config {config.path}"
    if rec_joints != cfg_joints:
        only_rec = sorted(f"{n}={i}" for n, i in rec_joints.items() if cfg_joints.get(n) != i)
        only_cfg = sorted(f"{n}={i}" for n, i in cfg_joints.items() if rec_joints.get(n) != i)
        raise RecordingMismatch(f"{where}: joint ids differ (recording has {', '.join(only_rec) or 'nothing else'}; "
                                f"config has {', '.join(only_cfg) or 'nothing else'}); pass the config it was recorded with "
                                "via --robot")
    cfg_models = {j.id: j.model.name for j in config.joints}
    if header["models"] != cfg_models:
        diff = sorted(f"id {i}: {header['models'].get(i)} vs {cfg_models.get(i)}"
                      for i in set(cfg_models) | set(header["models"]) if header["models"].get(i) != cfg_models.get(i))
        raise RecordingMismatch(f"{where}: servo models differ (recording vs config: {'; '.join(diff)})")
    if (header["backend"], float(header["protocol"])) != (config.bus.backend, float(config.bus.protocol)):
        raise RecordingMismatch(f"{where}: bus differs (recording {header['backend']} protocol {header['protocol']:g}, "
                                f"config {config.bus.backend} protocol {config.bus.protocol:g})")
    notes = []
    if int(header["baudrate"]) != int(config.bus.baudrate):
        notes.append(BusIssue("config", "warning", 1, 0.0, f"recorded at {header['baudrate']} baud, config says "
                              f"{config.bus.baudrate}"))
    if str(header["robot"]) != config.name:
        notes.append(BusIssue("config", "warning", 1, 0.0, f"recorded as robot {header['robot']!r}, checked against "
                              f"{config.name!r} (same joints, ids and servos)"))
    return notes


# ---------------------------------------------------------------------------------------------- checks


def check_recording(config: RobotConfig, path: str | Path, margin_deg: float = 0.0, *,
                    allow_partial_last_line: bool = False) -> RecordingReport:
    """Check a bus recording against ``config`` (see the module docstring for what and how).

    Raises RecordingError (RecordingMismatch) for a file that cannot be checked: unreadable, no
    header, a config of another robot, or no goal frames at all.
    """
    header, packets, issues = read_log(path, allow_partial_last_line=allow_partial_last_line)
    issues += match_config(path, header, config)
    names = {j.id: j.name for j in config.joints}
    column = {j.id: c for c, j in enumerate(config.joints)}
    known = set(column) | set(config.imu.device_ids)  # the IMU (the OP3's OpenCR) answers on the bus too
    model = config.joints[0].model
    goal_addr, goal_len = model.addr_goal_position, model.len_goal_position
    signed = goal_len == 4  # Dynamixel X goal position is a signed 32-bit register

    timing_t, timing_line = [], []  # every goal write, valid or not
    frames_t, frames_line, frames_rows = [], [], []
    models = {j.id: j.model for j in config.joints}
    settings: list[SettingWrite] = []
    for p in packets:
        if p.parsed is None or p.problem:
            issues.append(BusIssue("packet", "error", p.line_no, p.t_s,
                                   f"{p.direction} packet malformed: {p.problem}", p.hex))
            if (p.direction == "tx" and p.parsed is not None
                    and p.parsed.instruction == wire.INST_SYNC_WRITE):
                timing_t.append(p.t_s)  # sent on time, ignored by the servos
                timing_line.append(p.line_no)
            continue
        pk = p.parsed
        if p.direction == "rx":
            issues += _rx_issues(p, pk, known, names)
            continue
        is_goal = pk.instruction == wire.INST_SYNC_WRITE and (pk.address, pk.data_length) == (goal_addr, goal_len)
        issues += _unknown_id_issues(p, pk, known, is_goal)
        setting = setting_write(p.line_no, p.t_s, pk, models[pk.packet_id]) if pk.packet_id in models else None
        if setting is not None:
            settings.append(setting)
        if is_goal:
            row, frame_issues = _goal_row(p, pk, goal_len, config, column, names, signed)
            issues += frame_issues
            frames_t.append(p.t_s)
            frames_line.append(p.line_no)
            frames_rows.append(row)
            timing_t.append(p.t_s)
            timing_line.append(p.line_no)

    if not frames_t:
        raise RecordingError(f"{path}: no goal-position frames to check (sync writes to address {goal_addr}); "
                             "was this recorded from a walk?")
    rate_hz = float(header.get("rate_hz", config.gait.rate_hz))  # a recording made at --rate R carries R
    timing, timing_issues = _frame_timing(rate_hz, np.array(timing_t), np.array(timing_line, dtype=int))
    issues += timing_issues

    health = health_report(packets, wire.framing_for(config.bus.backend, config.bus.protocol), models,
                           health_thresholds(config), names)
    issues += [BusIssue("health", f.severity, f.line_no, f.t_s, f.message) for f in health.findings]

    t_s, lines, ticks = _motion_samples(config, np.array(frames_t), np.array(frames_line),
                                        np.array(frames_rows, dtype=float))
    angles_deg = np.degrees(ticks_to_angles(config, ticks))
    joints = check_trajectory(config, t_s, angles_deg, margin_deg)
    order = {k: i for i, k in enumerate(BUS_KIND_ORDER)}
    issues.sort(key=lambda i: (order[i.kind], i.line_no))
    return RecordingReport(path=str(path), robot=str(header["robot"]), backend=str(header["backend"]),
                           protocol=float(header["protocol"]), n_packets=len(packets),
                           n_tx=sum(1 for p in packets if p.direction == "tx"),
                           n_rx=sum(1 for p in packets if p.direction == "rx"), n_goal_frames=len(frames_t),
                           timing=timing, issues=tuple(issues), joints=joints,
                           sample_lines=tuple(int(x) for x in lines), sample_t_s=tuple(float(x) for x in t_s),
                           settings=tuple(settings), settings_text=tuple(describe_settings(tuple(settings), models)),
                           health=health, health_text=tuple(health.lines(names)))


def _id_label(servo_id: int, names: dict[int, str]) -> str:
    return f"id {servo_id} ({names[servo_id]})" if servo_id in names else f"id {servo_id}"


def _rx_issues(p: _Logged, pk, known: set[int], names: dict[int, str]) -> list[BusIssue]:
    out = []
    if pk.packet_id not in known:
        out.append(BusIssue("ids", "error", p.line_no, p.t_s,
                            f"status packet from id {pk.packet_id}, which is not in the config", p.hex))
    elif pk.error:
        out.append(BusIssue("status", "warning", p.line_no, p.t_s,
                            f"{_id_label(pk.packet_id, names)} reported error 0x{pk.error:02X}", p.hex))
    return out


def _unknown_id_issues(p: _Logged, pk, known: set[int], is_goal: bool) -> list[BusIssue]:
    if pk.instruction in (wire.INST_SYNC_WRITE, wire.INST_SYNC_READ):
        if pk.packet_id != wire.BROADCAST_ID:
            return [BusIssue("ids", "error", p.line_no, p.t_s,
                             f"sync packet sent to id {pk.packet_id}, not to broadcast {wire.BROADCAST_ID}", p.hex)]
        if is_goal:
            return []  # the goal frame check names its ids
        unknown = [i for i in pk.ids if i not in known]
    else:
        unknown = [i for i in pk.ids if i not in known and i != wire.BROADCAST_ID]
    if not unknown:
        return []
    return [BusIssue("ids", "error", p.line_no, p.t_s,
                     f"tx packet addresses id {', '.join(map(str, unknown))}, not in the config", p.hex)]


def _goal_row(p: _Logged, pk, goal_len: int, config: RobotConfig, column: dict[int, int],
              names: dict[int, str], signed: bool) -> tuple[np.ndarray, list[BusIssue]]:
    """Goal ticks of one frame in config joint order (NaN where a joint is not addressed) and its id issues."""
    body = pk.data
    row = np.full(len(config.joints), np.nan)
    issues = []
    stride = goal_len + 1
    if len(body) % stride:
        issues.append(BusIssue("packet", "error", p.line_no, p.t_s,
                               f"goal frame payload of {len(body)} bytes is not a whole number of "
                               f"{stride}-byte (id + goal) entries", p.hex))
    order = config.joints[0].model.byte_order
    ids_sent = []
    for o in range(0, len(body) - goal_len, stride):
        servo_id = body[o]
        ids_sent.append(servo_id)
        if servo_id in column:
            row[column[servo_id]] = int.from_bytes(body[o + 1:o + 1 + goal_len], order, signed=signed)
    unknown = sorted({i for i in ids_sent if i not in column})
    repeated = sorted({i for i in ids_sent if ids_sent.count(i) > 1})
    missing = [j.id for j in config.joints if j.id not in ids_sent]
    if missing:
        issues.append(BusIssue("ids", "error", p.line_no, p.t_s, "goal frame lacks "
                               + ", ".join(_id_label(i, names) for i in missing), p.hex))
    if unknown:
        issues.append(BusIssue("ids", "error", p.line_no, p.t_s, "goal frame addresses unknown "
                               + ", ".join(f"id {i}" for i in unknown) + " (not in the config)", p.hex))
    if repeated:
        issues.append(BusIssue("ids", "error", p.line_no, p.t_s, "goal frame repeats "
                               + ", ".join(_id_label(i, names) for i in repeated), p.hex))
    return row, issues


def _frame_timing(rate_hz: float, t: np.ndarray, lines: np.ndarray) -> tuple[FrameTiming, list[BusIssue]]:
    period = 1.0 / rate_hz
    limit = MAX_GAP_PERIODS * period
    gaps = np.diff(t)
    issues = []
    late = np.flatnonzero(gaps > limit + 1e-9)
    back = np.flatnonzero(gaps < 0)
    for k in late:
        issues.append(BusIssue("timing", "error", int(lines[k + 1]), float(t[k + 1]),
                               f"goal frame late: {gaps[k] * 1000:.2f} ms ({gaps[k] / period:.2f} periods) after the "
                               f"previous one (line {lines[k]}, t={t[k]:.3f} s); limit {limit * 1000:.2f} ms "
                               f"({MAX_GAP_PERIODS:g} periods at {rate_hz:g} Hz)"))
    for k in back:
        issues.append(BusIssue("timing", "error", int(lines[k + 1]), float(t[k + 1]),
                               f"goal frame time goes backwards by {-gaps[k] * 1000:.2f} ms from the previous one "
                               f"(line {lines[k]}, t={t[k]:.3f} s)"))
    if len(gaps):
        w = int(np.argmax(gaps))
        timing = FrameTiming(rate_hz, period, len(t), float(gaps.mean()), float(np.percentile(gaps, 99)),
                             float(gaps[w]), float(t[w + 1]), int(lines[w + 1]), limit, len(late), len(back))
    else:
        timing = FrameTiming(rate_hz, period, len(t), 0.0, 0.0, 0.0, float(t[0]) if len(t) else 0.0,
                             int(lines[0]) if len(lines) else 0, limit, 0, 0)
    return timing, issues


def _motion_samples(config: RobotConfig, t: np.ndarray, lines: np.ndarray, rows: np.ndarray):
    """(t_s, line, ticks) of the goal frames as the servos followed them: missing joints keep their
    previous goal; a frame not later than the one before supersedes it (same time) or is dropped
    (earlier: reported as a timing error)."""
    rows = rows.copy()
    for c in range(rows.shape[1]):
        col = rows[:, c]
        known = ~np.isnan(col)
        if not known.any():
            col[:] = config.joints[c].zero_tick
            continue
        idx = np.where(known, np.arange(len(col)), 0)
        np.maximum.accumulate(idx, out=idx)
        filled = col[idx]
        first = int(np.argmax(known))
        filled[:first] = col[first]
        rows[:, c] = filled
    # Keep the frames that set a new latest time; among equal times the last one wins.
    running = np.maximum.accumulate(t)
    new_time = t >= running  # not earlier than anything before
    keep = new_time.copy()
    keep_idx = np.flatnonzero(new_time)
    if len(keep_idx) > 1:
        same_as_next = t[keep_idx[:-1]] == t[keep_idx[1:]]
        keep[keep_idx[:-1][same_as_next]] = False
    return t[keep], lines[keep], rows[keep]
