"""What an emulated chain is made of: its servos and bus, the faults to inject, how servos warm, and the
scripted hand (ticks per servo, from a CSV here or from a trajectory by the app layer)."""

from __future__ import annotations

from dataclasses import dataclass, field

from gaitbot.servos.models import ServoModel

FAULT_KINDS = ("overload", "overheating", "voltage")


@dataclass
class Faults:
    """Faults to inject, once ``after_frames`` goal frames and ``after_s`` seconds passed: silent, late and
    corrupt replies, error bits, a port that disappears."""

    silent: set[int] = field(default_factory=set)
    late_s: dict[int, float] = field(default_factory=dict)
    corrupt_fraction: float = 0.0
    corrupt_ids: set[int] | None = None  # None: every servo
    errors: dict[int, set[str]] = field(default_factory=dict)
    after_frames: int = 0
    after_s: float = 0.0
    close_after_frames: int | None = None
    close_after_s: float | None = None


@dataclass
class Hand:
    """Ticks per servo id, one entry per sample; ``rate_hz`` None: one sample per read cycle."""

    ticks: dict[int, list[int]]
    rate_hz: float | None = None

    def __post_init__(self) -> None:
        lengths = {len(v) for v in self.ticks.values()}
        if len(lengths) != 1 or 0 in lengths:
            raise ValueError("the hand needs the same number (at least one) of samples for every servo")
        if self.rate_hz is not None and not self.rate_hz > 0:
            raise ValueError(f"--hand-rate must be a positive rate in Hz, got {self.rate_hz}")

    @property
    def samples(self) -> int:
        return len(next(iter(self.ticks.values())))


@dataclass
class Heat:
    """How servos warm and cool: with torque on and ``load`` (0..1 of the maximum torque) held, the temperature
    rises by ``heat_c_per_s`` x load^2 (resistive heating) and relaxes towards ``ambient_c`` with time constant
    ``cool_time_s``: T(t) = T_eq + (T0 - T_eq) exp(-t / tau), T_eq = ambient + heat x load^2 x tau. The
    defaults (0.5 C/s at full load, 300 s) make a stalled servo overheat in about a minute and a lightly
    loaded one stay near ambient: an order of magnitude, not a measured servo."""

    ambient_c: float = 25.0
    heat_c_per_s: float = 0.5
    cool_time_s: float = 300.0


@dataclass
class EmulatorConfig:
    """A chain to emulate: its bus, its servos (or factory-fresh ones), faults, heat, supply and hand."""

    backend: str
    protocol: float
    models: dict[int, ServoModel]
    baudrate: int = 1_000_000
    faults: Faults = field(default_factory=Faults)
    log_path: str | None = None
    robot: str = "emulated"
    joints: dict[str, int] | None = None
    seed: int = 0
    return_delay_us: float | None = None  # overrides every servo's Return Delay Time register
    hand: Hand | None = None  # moves servos whose torque is off (see the module docstring)
    fresh: tuple[ServoModel, ...] = ()  # factory-fresh servos (id 1, factory rate) instead of ``models``
    one_at_a_time: bool = False  # only one servo connected at a time (plug_next() swaps it for the next)
    heat: Heat = field(default_factory=Heat)
    loads_pct: dict[int, float] = field(default_factory=dict)  # servo id -> load it holds with torque on, %
    temperatures_c: dict[int, float] = field(default_factory=dict)  # servo id -> temperature at the start
    supply_v: float | None = None  # None: the first servo's usual supply (its Present Voltage factory value)
    voltage_sag_v_per_s: float = 0.0  # the supply falls this fast once faults are active
    imu: object | None = None  # an IMU device on the line (gaitbot.bus.imu_device.ImuDevice), answering at its id
    model_numbers: dict[int, int] = field(default_factory=dict)  # servo id -> the model number it reports
    start_ticks: dict[int, int] = field(default_factory=dict)  # servo id -> where it is at power-on (else centre)
    restored: tuple = ()  # (model, EEPROM bytes) per servo, from a state file: these servos instead of ``models``
    state_path: str | None = None  # keep every servo's EEPROM in this file (gaitbot.emulator.state)


def hand_from_ticks(path: str, rate_hz: float | None = None) -> Hand:
    """A hand from a CSV of raw ticks: a header of servo ids, then one row per sample (docs/emulator.md)."""
    import csv

    with open(path, newline="", encoding="utf-8") as f:
        rows = [row for row in csv.reader(f) if row and any(cell.strip() for cell in row)]
    if len(rows) < 2:
        raise ValueError(f"--hand-ticks {path}: needs a header of servo ids and at least one row of ticks")
    try:
        ids = [int(cell) for cell in rows[0]]
        samples = [[int(cell) for cell in row] for row in rows[1:]]
    except ValueError as exc:
        raise ValueError(f"--hand-ticks {path}: {exc} (the header holds servo ids, the rows whole ticks)") from None
    if any(len(row) != len(ids) for row in samples):
        raise ValueError(f"--hand-ticks {path}: every row needs {len(ids)} ticks, one per servo id in the header")
    return Hand({servo_id: [row[k] for row in samples] for k, servo_id in enumerate(ids)}, rate_hz)
