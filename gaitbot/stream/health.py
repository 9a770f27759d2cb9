"""Servo health while a session runs: readings in, warnings out, and a safe stop before a servo's own limits.

The session reads one servo's health block per frame (the read-back that goes round the servos:
gaitbot.stream.session) and hands each reading to :meth:`HealthMonitor.observe`. A reading at or past a
warning threshold is reported once per servo and kind (``on_warning``, and :attr:`HealthMonitor.status`
for a status line); one at or past a stop threshold raises :class:`ServoHealthStop`, a BusError, so the
session stops as for a bus fault: the same braking ramp to the stand pose, exit status 1, the servo and
the reading named. Thresholds come from gaitbot.robot.health (each model's defaults and the config's
``[health]``); docs/bring-up.md explains them.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

from gaitbot.bus.base import BusError, ReadBack
from gaitbot.robot.health import health_thresholds
from gaitbot.servos.health import HealthBlock, HealthReading, HealthThresholds, decode_health, health_block, servo_limits


class ServoHealthStop(BusError):
    """A servo's temperature or input voltage reached its stop threshold (``kind``: "temperature" or
    "voltage"); ``reading`` is the reading that did it."""

    def __init__(self, message: str, *, servo_id: int, kind: str, reading: HealthReading) -> None:
        super().__init__(message, servo_id=servo_id)
        self.kind = kind
        self.reading = reading


@dataclass(frozen=True)
class Extreme:
    """The worst value seen of one kind, which servo, and when (the session's clock, seconds)."""

    servo_id: int
    value: float
    t_s: float


class HealthMonitor:
    """Watches the readings of a session's servos against ``thresholds`` (servo id -> HealthThresholds).

    ``names`` (servo id -> joint name) and ``models`` (servo id -> model name) make messages readable;
    ``on_warning(text)`` is called once per servo and kind when a warning threshold is first reached;
    ``clock()`` (seconds) stamps the extremes. ``hottest``, ``lowest_voltage`` and ``peak_load`` hold the
    worst readings so far; ``readings`` counts them.
    """

    def __init__(self, thresholds: Mapping[int, HealthThresholds], names: Mapping[int, str] | None = None,
                 models: Mapping[int, str] | None = None, on_warning: Callable[[str], None] | None = None,
                 clock: Callable[[], float] | None = None, blocks: Mapping[int, HealthBlock] | None = None) -> None:
        self.thresholds = dict(thresholds)
        self.blocks = dict(blocks or {})  # servo id -> the registers its read-back reads (servos.health)
        self.names = dict(names or {})
        self.models = dict(models or {})
        self.on_warning = on_warning
        self.clock = clock or (lambda: 0.0)
        self.status = ""
        self.readings = 0
        self.last_read_back: ReadBack | None = None  # the latest answer (its present ticks: the live view's)
        self.hottest: Extreme | None = None
        self.lowest_voltage: Extreme | None = None
        self.peak_load: Extreme | None = None
        self._warned: set[tuple[int, str]] = set()

    @classmethod
    def for_robot(cls, config, on_warning: Callable[[str], None] | None = None,
                  clock: Callable[[], float] | None = None) -> "HealthMonitor":
        """The monitor of a robot config's servos: its thresholds (models' defaults, its ``[health]``)."""
        return cls(health_thresholds(config), {j.id: j.name for j in config.joints},
                   {j.id: j.model.name for j in config.joints}, on_warning, clock,
                   {j.id: health_block(j.model) for j in config.joints})

    def observe_read_back(self, answer: ReadBack) -> None:
        """An answered per-frame read-back (gaitbot.stream.readback) whose data is this servo's health block."""
        self.last_read_back = answer
        block = self.blocks.get(answer.servo_id)
        if block is not None and answer.data is not None and len(answer.data) >= block.length:
            self.observe(decode_health(block, answer.servo_id, answer.data[:block.length]))

    def label(self, servo_id: int) -> str:
        name = self.names.get(servo_id)
        return f"servo {servo_id} ({name})" if name else f"servo {servo_id}"

    def observe(self, reading: HealthReading) -> None:
        """Take one reading: keep the extremes, warn, or raise ServoHealthStop."""
        servo_id = reading.servo_id
        t = self.thresholds.get(servo_id)
        if t is None:
            return
        now_s = self.clock()
        self.readings += 1
        if self.hottest is None or reading.temperature_c > self.hottest.value:
            self.hottest = Extreme(servo_id, reading.temperature_c, now_s)
        if self.lowest_voltage is None or reading.voltage_v < self.lowest_voltage.value:
            self.lowest_voltage = Extreme(servo_id, reading.voltage_v, now_s)
        if reading.load_pct is not None and (self.peak_load is None or abs(reading.load_pct) > self.peak_load.value):
            self.peak_load = Extreme(servo_id, abs(reading.load_pct), now_s)
        who = self.label(servo_id)
        model = self.models.get(servo_id)
        if reading.temperature_c >= t.stop_temperature_c:
            own = ""
            if model:
                own = f"; the {model} shuts itself down at {servo_limits(model).shutdown_temperature_c:g} °C"
            raise ServoHealthStop(f"{who} is at {reading.temperature_c:g} °C, at or above its stop temperature "
                                  f"{t.stop_temperature_c:g} °C{own}; let it cool before walking again",
                                  servo_id=servo_id, kind="temperature", reading=reading)
        if reading.voltage_v <= t.stop_voltage_v:
            raise ServoHealthStop(f"{who} has {reading.voltage_v:.1f} V input voltage, at or under its stop voltage "
                                  f"{t.stop_voltage_v:.1f} V; charge or change the battery",
                                  servo_id=servo_id, kind="voltage", reading=reading)
        if reading.temperature_c >= t.warn_temperature_c:
            self._warn(servo_id, "temperature", f"{who} at {reading.temperature_c:g} °C (warning at "
                                                f"{t.warn_temperature_c:g}, stop at {t.stop_temperature_c:g} °C)")
        if reading.voltage_v <= t.warn_voltage_v:
            self._warn(servo_id, "voltage", f"{who} input voltage {reading.voltage_v:.1f} V (warning at "
                                            f"{t.warn_voltage_v:.1f}, stop at {t.stop_voltage_v:.1f} V)")
        if reading.load_pct is not None and abs(reading.load_pct) >= t.warn_load_pct:
            self._warn(servo_id, "load", f"{who} load {abs(reading.load_pct):g} % (warning at {t.warn_load_pct:g} %)")

    def _warn(self, servo_id: int, kind: str, text: str) -> None:
        self.status = text
        if (servo_id, kind) in self._warned:
            return
        self._warned.add((servo_id, kind))
        if self.on_warning is not None:
            self.on_warning(text)

    def summary(self) -> str:
        """One line: the hottest servo, the lowest voltage and the peak load seen ("" before any reading)."""
        if not self.readings:
            return ""
        parts = []
        if self.hottest is not None:
            parts.append(f"hottest {self.label(self.hottest.servo_id)} {self.hottest.value:g} °C")
        if self.lowest_voltage is not None:
            parts.append(f"lowest voltage {self.lowest_voltage.value:.1f} V at {self.label(self.lowest_voltage.servo_id)}")
        if self.peak_load is not None:
            parts.append(f"peak load {self.peak_load.value:g} % at {self.label(self.peak_load.servo_id)}")
        return f"servo health over {self.readings} reads: " + ", ".join(parts)
