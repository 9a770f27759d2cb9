"""Servo health in a recorded run, for ``gaitbot check``: the health blocks the session read, decoded again.

A walk (or a recording by hand) reads one servo's health block per frame (gaitbot.stream.health); its bus
recording holds each READ instruction and the status packet that answered it. Here every READ of a model's
health block (gaitbot.servos.health) is paired with the next clean status packet of that servo and decoded:
the hottest servo, the lowest input voltage and the peak load of the run, and each reading at or past the
robot's thresholds (gaitbot.robot.health) as an issue: a warning threshold a warning, a stop threshold an
error (the run went where a walk stops).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

from gaitbot.servos import wire
from gaitbot.servos.health import HealthReading, HealthThresholds, decode_health, health_block
from gaitbot.servos.models import ServoModel


@dataclass(frozen=True)
class RecordedReading:
    """A health reading found in a recording: ``line_no`` of its status packet, ``t_s`` its time."""

    line_no: int
    t_s: float
    reading: HealthReading


@dataclass(frozen=True)
class HealthFinding:
    """A reading past a threshold: ``severity`` "warning" or "error" (a stop threshold), ``message`` for people."""

    severity: str
    line_no: int
    t_s: float
    servo_id: int
    message: str


@dataclass
class HealthReport:
    """The health reads of a recording: how many, the extremes (None: no reading) and the findings."""

    n_readings: int = 0
    hottest: RecordedReading | None = None
    lowest_voltage: RecordedReading | None = None
    peak_load: RecordedReading | None = None
    findings: list[HealthFinding] = field(default_factory=list)

    def lines(self, names: dict[int, str]) -> list[str]:
        """People's lines: the extremes, one each ("no servo health reads" when there are none)."""
        if not self.n_readings:
            return ["servo health: no health reads in this recording"]

        def who(r: RecordedReading) -> str:
            name = names.get(r.reading.servo_id)
            return f"servo {r.reading.servo_id}" + (f" ({name})" if name else "")

        out = [f"servo health over {self.n_readings} reads:"]
        h, v, p = self.hottest, self.lowest_voltage, self.peak_load
        out.append(f"  hottest servo: {who(h)} at {h.reading.temperature_c:g} °C, t={h.t_s:.3f} s (line {h.line_no})")
        out.append(f"  lowest voltage: {v.reading.voltage_v:.1f} V at {who(v)}, t={v.t_s:.3f} s (line {v.line_no})")
        if p is not None:
            out.append(f"  peak load: {abs(p.reading.load_pct):g} % at {who(p)}, t={p.t_s:.3f} s (line {p.line_no})")
        else:
            out.append("  peak load: not reported by these servos")
        return out

    def to_dict(self) -> dict:
        def one(r: RecordedReading | None) -> dict | None:
            return None if r is None else {"line_no": r.line_no, "t_s": r.t_s, **r.reading.to_dict()}

        return {"n_readings": self.n_readings, "hottest": one(self.hottest), "lowest_voltage": one(self.lowest_voltage),
                "peak_load": one(self.peak_load), "findings": [asdict(f) for f in self.findings]}


def health_report(packets, framing: str, models: dict[int, ServoModel], thresholds: dict[int, HealthThresholds],
                  names: dict[int, str], collect: list[RecordedReading] | None = None) -> HealthReport:
    """Decode every health read among ``packets`` (the recording check's parsed packets, in file order);
    ``collect`` (a list) receives every reading, for a plot."""
    blocks = {servo_id: health_block(model) for servo_id, model in models.items()}
    asked: dict[int, bool] = {}
    report = HealthReport()
    warned: set[tuple[int, str]] = set()
    for p in packets:
        pk = p.parsed
        if pk is None or not pk.checksum_ok:
            continue
        if p.direction == "tx":
            block = blocks.get(pk.packet_id)
            if pk.instruction == wire.INST_READ and block is not None:
                # the block itself, or the block and a few bytes more: a walk's read-back asks a servo whose
                # last read went unanswered for a longer one, so that a late reply cannot pass for its answer
                # (docs/bus-faults.md, "Matched"); the block leads either way
                asked[pk.packet_id] = (pk.address == block.address and pk.data_length is not None
                                       and pk.data_length >= block.length)
            continue
        servo_id = pk.packet_id
        if not asked.pop(servo_id, False):
            continue
        block = blocks[servo_id]
        if len(pk.data) < block.length:
            continue
        found = RecordedReading(p.line_no, p.t_s, decode_health(block, servo_id, bytes(pk.data[:block.length])))
        _take(report, found)
        if collect is not None:
            collect.append(found)
        _judge(report, found, thresholds.get(servo_id), names, warned)
    return report


def _take(report: HealthReport, r: RecordedReading) -> None:
    report.n_readings += 1
    if report.hottest is None or r.reading.temperature_c > report.hottest.reading.temperature_c:
        report.hottest = r
    if report.lowest_voltage is None or r.reading.voltage_v < report.lowest_voltage.reading.voltage_v:
        report.lowest_voltage = r
    load = r.reading.load_pct
    if load is not None and (report.peak_load is None or abs(load) > abs(report.peak_load.reading.load_pct)):
        report.peak_load = r


def _judge(report: HealthReport, r: RecordedReading, t: HealthThresholds | None, names: dict[int, str],
           warned: set[tuple[int, str]]) -> None:
    """A finding the first time a servo reaches each threshold (stop thresholds always)."""
    if t is None:
        return
    servo_id, reading = r.reading.servo_id, r.reading
    who = f"servo {servo_id}" + (f" ({names[servo_id]})" if servo_id in names else "")
    checks = (
        ("error", "temperature-stop", reading.temperature_c >= t.stop_temperature_c,
         f"{who} at {reading.temperature_c:g} °C, at or above the stop temperature {t.stop_temperature_c:g} °C"),
        ("error", "voltage-stop", reading.voltage_v <= t.stop_voltage_v,
         f"{who} input voltage {reading.voltage_v:.1f} V, at or under the stop voltage {t.stop_voltage_v:.1f} V"),
        ("warning", "temperature", reading.temperature_c >= t.warn_temperature_c,
         f"{who} at {reading.temperature_c:g} °C, at or above the warning temperature {t.warn_temperature_c:g} °C"),
        ("warning", "voltage", reading.voltage_v <= t.warn_voltage_v,
         f"{who} input voltage {reading.voltage_v:.1f} V, at or under the warning voltage {t.warn_voltage_v:.1f} V"),
        ("warning", "load", reading.load_pct is not None and abs(reading.load_pct) >= t.warn_load_pct,
         f"{who} load {abs(reading.load_pct or 0):g} %, at or above the warning load {t.warn_load_pct:g} %"),
    )
    for severity, kind, crossed, message in checks:
        if crossed and (servo_id, kind) not in warned:
            warned.add((servo_id, kind))
            report.findings.append(HealthFinding(severity, r.line_no, r.t_s, servo_id, message))
