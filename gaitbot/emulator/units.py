"""One emulated servo: its model, control table, layout, where it is, how warm, and whether it is plugged in."""

from __future__ import annotations

from dataclasses import dataclass

from gaitbot.bus.dry_run import DryRunPort
from gaitbot.servos import vendor
from gaitbot.servos.health import health_block
from gaitbot.servos.models import SERVO_MODELS, ServoModel
from gaitbot.servos.status import hardware_error_bits

#: Protocol 2.0 error number 7, "Access Error": an EEPROM write while torque is on (e-Manual Protocol 2.0).
ACCESS_ERROR = 7


@dataclass(frozen=True)
class Layout:
    """Control-table addresses the emulator needs beyond ServoModel's, and the factory values it starts
    with (address, size, value): all read from the vendor's control table (gaitbot.servos)."""

    id_addr: int
    return_delay_addr: int
    status_return_addr: int
    moving_addr: int
    hardware_error_addr: int | None  # Hardware Error Status (Dynamixel X, XL-320) or Servo Status (Feetech)
    hardware_error_bits: dict[str, int]  # fault kind -> its bit in that register
    eeprom_end: int  # first RAM address
    lock_addr: int | None  # Feetech's Lock flag
    temperature_limit_addr: int
    min_voltage: tuple[int, int]  # Min Voltage Limit (address, size)
    max_voltage: tuple[int, int]
    baud_addr: int
    initial: tuple[tuple[int, int, int], ...]

    @classmethod
    def of(cls, model: ServoModel) -> "Layout":
        table = model.control_table
        hardware = table.get("Hardware Error Status") or table.get("Servo Status")
        bits = {("voltage" if name == "input voltage" else name): bit
                for bit, name in hardware_error_bits(model.name).items()}
        lock = table.get("Lock")
        temperature = table.get("Temperature Limit") or table["Max Temperature Limit"]
        return cls(table["ID"].address, table["Return Delay Time"].address, table["Status Return Level"].address,
                   table["Moving"].address, hardware.address if hardware is not None else None, bits,
                   vendor(model.family).EEPROM_END[model.name], lock.address if lock is not None else None,
                   temperature.address, tuple(table["Min Voltage Limit"][:2]), tuple(table["Max Voltage Limit"][:2]),
                   table["Baud Rate"].address,
                   tuple((r.address, r.size, r.factory) for r in table.values() if r.factory is not None))


LAYOUTS = {name: Layout.of(model) for name, model in SERVO_MODELS.items()}
_REGISTERS = {name: model.control_table for name, model in SERVO_MODELS.items()}


@dataclass(eq=False)
class Servo:
    """One emulated servo: its model, control table (``saved``: the EEPROM as it survives a power cycle),
    where it is (``present`` ticks), how warm, what it holds, and whether it is plugged in."""

    index: int
    model: ServoModel
    table: bytearray
    saved: bytearray
    present: float
    temperature_c: float
    load_pct: float = 0.0
    connected: bool = True
    rate_blind: bool = False  # made for a rate its register cannot hold: hears any rate
    moved_at_s: float | None = None  # None: time has not started for it (no packet yet)
    pending_error: int | None = None  # the error of the next status packet (a refused write)
    shown: tuple | None = None  # (temperature, voltage, torque, load) the registers show now

    @property
    def layout(self) -> Layout:
        return LAYOUTS[self.model.name]

    @property
    def block(self):
        return health_block(self.model)

    @property
    def servo_id(self) -> int:
        return self.table[self.layout.id_addr]

    @property
    def rate(self) -> int | None:
        return DryRunPort.servo_rate(self.model, self.table)

    def register(self, name: str) -> int:
        r = _REGISTERS[self.model.name][name]
        return int.from_bytes(self.table[r.address:r.address + r.size], self.model.byte_order)
