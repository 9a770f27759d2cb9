"""A servo's health as data: which registers say it, how to decode them, and the limits a servo keeps.

Three kinds of fact, each written once here from the vendors' published manuals (the ROBOTIS e-Manual's
control-table pages of each model, "XL430-W250", "XM430-W350", "XL-320", "AX-12/AX-12A", and their
specifications; Feetech's "SMS/STS series memory table" and "SCSCL series memory table" and the STS3215 /
SCS0009 datasheets):

* **The health block** of each model: the smallest contiguous run of control-table bytes holding present
  position, input voltage and temperature (and present load where the model has one), so that one READ
  of one servo per frame returns all of them (:func:`health_block`, :func:`decode_health`).
* **The servo's own limits**: the shutdown temperature (its Temperature Limit register as shipped) and the
  lowest input voltage it is specified for, from the datasheet (:data:`SERVO_LIMITS`).
* **gaitbot's default thresholds** built on them (:func:`default_thresholds`): warn 10 C and stop 5 C
  below the shutdown temperature; stop under the datasheet's minimum input voltage and warn 0.5 V above
  it; warn at 80 % load (Feetech's factory "overload torque", above which its protection timer starts).
  These margins are gaitbot's choice, not vendor facts (docs/bring-up.md says why).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

from gaitbot.servos import dynamixel, feetech
from gaitbot.servos.registers import ControlTable, Register

#: Where a model keeps its input voltage (0.1 V a unit on every model gaitbot knows).
_VOLTAGE_NAMES = ("Present Input Voltage", "Present Voltage")
#: Present Load encodings: "signed" two's complement (X series, 0.1 %), "bit10" magnitude in bits 0..9 (0.1 %)
#: and the direction in bit 10 (AX, XL-320, Feetech; 1 = clockwise, reported negative).
LOAD_ENCODING = {"XL430-W250": "signed", "XL-320": "bit10", "AX-12A": "bit10", "STS3215": "bit10",
                 "SCS0009": "bit10"}


def _table(model_name: str) -> ControlTable:
    for module in (dynamixel, feetech):
        if model_name in module.CONTROL_TABLES:
            return module.CONTROL_TABLES[model_name]
    raise KeyError(f"no control table for servo model {model_name!r}")


@dataclass(frozen=True)
class HealthBlock:
    """The contiguous registers one READ returns: ``address`` .. ``address + length``; each field's register."""

    model_name: str
    address: int
    length: int
    position: Register
    voltage: Register
    temperature: Register
    load: Register | None  # None: the model reports no load (XM430-W350: a current at that address)
    load_encoding: str | None
    byte_order: str

    def field(self, data: bytes, register: Register) -> int:
        start = register.address - self.address
        return int.from_bytes(data[start:start + register.size], self.byte_order)


@lru_cache(maxsize=None)
def health_block(model) -> HealthBlock:
    """The health block of a servo model (a ServoModel), from its control table (the control-table pages:
    XL430 126..146, 21 bytes; XM430 132..146, 15 (no load); XL-320 37..46, 10; AX 36..43, 8; STS/SCS 56..63, 8)."""
    model_name, byte_order = model.name, model.byte_order
    table = _table(model_name)
    voltage = next(table[name] for name in _VOLTAGE_NAMES if name in table)
    load = table.get("Present Load")
    registers = [table["Present Position"], voltage, table["Present Temperature"]] + ([load] if load else [])
    start = min(r.address for r in registers)
    end = max(r.address + r.size for r in registers)
    return HealthBlock(model_name, start, end - start, table["Present Position"], voltage,
                       table["Present Temperature"], load, LOAD_ENCODING.get(model_name) if load else None,
                       byte_order)


@dataclass(frozen=True)
class HealthReading:
    """One servo's health at one moment: present position (ticks), temperature (C), input voltage (V) and
    present load (% of the maximum, signed; None where the model has no load register)."""

    servo_id: int
    position_ticks: int
    temperature_c: float
    voltage_v: float
    load_pct: float | None = None

    def to_dict(self) -> dict:
        return {"id": self.servo_id, "position_ticks": self.position_ticks, "temperature_c": self.temperature_c,
                "voltage_v": self.voltage_v, "load_pct": self.load_pct}


def decode_load(raw: int, encoding: str, size: int) -> float:
    """Present Load as a signed percentage: two's complement, or magnitude with bit 10 the direction."""
    if encoding == "signed":
        if raw >= 1 << (8 * size - 1):
            raw -= 1 << (8 * size)
        return raw / 10.0
    magnitude = raw & 0x3FF
    return -magnitude / 10.0 if raw & 0x400 else magnitude / 10.0


def encode_load(load_pct: float, encoding: str, size: int) -> int:
    """The register value of a load (the emulator's side of :func:`decode_load`)."""
    tenths = int(round(max(-100.0, min(100.0, load_pct)) * 10))
    if encoding == "signed":
        return tenths % (1 << (8 * size))
    return abs(tenths) | (0x400 if tenths < 0 else 0)


def decode_health(block: HealthBlock, servo_id: int, data: bytes) -> HealthReading:
    """A HealthReading from the bytes of one READ of ``block``. Position: 4-byte registers are two's
    complement (X series), 2-byte ones unsigned, as the bus decodes them."""
    if len(data) < block.length:
        raise ValueError(f"servo {servo_id}: health block of {block.length} bytes expected, got {len(data)}")
    start = block.position.address - block.address
    position = int.from_bytes(data[start:start + block.position.size], block.byte_order,
                              signed=block.position.size == 4)
    load = None
    if block.load is not None:
        load = decode_load(block.field(data, block.load), block.load_encoding, block.load.size)
    return HealthReading(servo_id, position, float(block.field(data, block.temperature)),
                         block.field(data, block.voltage) / 10.0, load)


@dataclass(frozen=True)
class ServoLimits:
    """What a servo model itself tolerates: it shuts down at ``shutdown_temperature_c`` (its Temperature
    Limit register as shipped) and is specified from ``min_input_v`` to ``max_input_v`` (datasheet);
    ``min_voltage_register_v`` is its Min Voltage Limit as shipped, the lowest any threshold may go."""

    shutdown_temperature_c: float
    min_input_v: float
    max_input_v: float
    min_voltage_register_v: float
    source: str


def _register_limits(model_name: str) -> tuple[float, float]:
    table = _table(model_name)
    temperature = table.get("Temperature Limit") or table["Max Temperature Limit"]
    return float(temperature.factory), table["Min Voltage Limit"].factory / 10.0


def _limits(model_name: str, min_input_v: float, max_input_v: float, source: str) -> ServoLimits:
    temperature_c, min_register_v = _register_limits(model_name)
    return ServoLimits(temperature_c, min_input_v, max_input_v, min_register_v, source)


#: The servo models' own limits (the e-Manual's specifications and Feetech's datasheets). Where sources disagree the safer figure is kept.
SERVO_LIMITS: dict[str, ServoLimits] = {
    # Temperature Limit 72 C; recommended 6.5..12.0 V (Min Voltage Limit register 6.0 V)
    "XL430-W250": _limits("XL430-W250", 6.5, 12.0, "ROBOTIS e-Manual XL430-W250 (dxl_x_info.yml)"),
    # Temperature Limit 80 C; recommended 10.0..14.8 V (register 9.5 V)
    "XM430-W350": _limits("XM430-W350", 10.0, 14.8, "ROBOTIS e-Manual XM430-W350 (dxl_x_info.yml)"),
    # Temperature Limit 65 C; recommended 6.0..8.4 V (register 6.0 V)
    "XL-320": _limits("XL-320", 6.0, 8.4, "ROBOTIS e-Manual XL-320"),
    # Temperature Limit 70 C; recommended 9.0..12.0 V (register 6.0 V)
    "AX-12A": _limits("AX-12A", 9.0, 12.0, "ROBOTIS e-Manual AX-12A"),
    # Max temperature limit 70 C; 6.0..7.4 V (Feetech's web table; its PDF says 4..7.4 V: the higher minimum
    # is kept) for the 7.4 V ST-3215-C001 (register 4.0 V)
    "STS3215": _limits("STS3215", 6.0, 7.4, "Feetech ST-3215-C001 specifications (ftservo-wiki official-specs.json)"),
    # Max temperature limit 70 C; 4.8..8.4 V (Waveshare SC09; Feetech gives 4..7.4 V: the higher minimum is kept)
    "SCS0009": _limits("SCS0009", 4.8, 8.4, "Waveshare SC09 wiki; Feetech SCS0009 specifications"),
}

#: gaitbot's margins (its choice, docs/bring-up.md): below the shutdown temperature, above the minimum voltage.
WARN_BELOW_SHUTDOWN_C = 10.0
STOP_BELOW_SHUTDOWN_C = 5.0
WARN_ABOVE_MIN_V = 0.5
WARN_LOAD_PCT = 80.0  # Feetech's factory "overload torque" (80 %), where its overload protection timer starts


@dataclass(frozen=True)
class HealthThresholds:
    """When gaitbot warns and when it stops a walk, for one servo."""

    warn_temperature_c: float
    stop_temperature_c: float
    warn_voltage_v: float
    stop_voltage_v: float
    warn_load_pct: float

    def to_dict(self) -> dict:
        return dict(self.__dict__)


def servo_limits(model_name: str) -> ServoLimits:
    try:
        return SERVO_LIMITS[model_name]
    except KeyError:
        raise KeyError(f"no health limits for servo model {model_name!r}") from None


def default_thresholds(model_name: str) -> HealthThresholds:
    """gaitbot's thresholds for a model: warn 10 C and stop 5 C below its shutdown temperature, stop under
    its minimum input voltage and warn 0.5 V above it, warn at 80 % load."""
    limits = servo_limits(model_name)
    return HealthThresholds(
        warn_temperature_c=limits.shutdown_temperature_c - WARN_BELOW_SHUTDOWN_C,
        stop_temperature_c=limits.shutdown_temperature_c - STOP_BELOW_SHUTDOWN_C,
        warn_voltage_v=round(limits.min_input_v + WARN_ABOVE_MIN_V, 2), stop_voltage_v=limits.min_input_v,
        warn_load_pct=WARN_LOAD_PCT)
