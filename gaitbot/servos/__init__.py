"""The servos room: vendor facts as data, importing nothing else of gaitbot.

One module per vendor (``dynamixel``, ``feetech``: control tables, model numbers, baud rates, id
ranges, error bits), the servo models built from them (``models``), packet framing written from the
protocol documents (``wire``) and status bytes in words (``status``). The list of backends is
written here and nowhere else.
"""

from __future__ import annotations

from types import ModuleType

from gaitbot.servos import dynamixel, feetech
from gaitbot.servos.registers import ControlTable, Register, RegisterWrite

#: Backend name -> its vendor module. The one list of the backends gaitbot speaks.
VENDORS: dict[str, ModuleType] = {dynamixel.NAME: dynamixel, feetech.NAME: feetech}
BACKENDS: tuple[str, ...] = tuple(VENDORS)

#: Return Delay Time assumed per status packet when budgeting the bus: 250 x 2 us is the factory
#: value on Dynamixel X, AX and XL-320; Feetech series differ by firmware, so the same (longer,
#: safe) figure is assumed for them.
ASSUMED_RETURN_DELAY_S = 500e-6


def vendor(backend: str) -> ModuleType:
    """The vendor module of ``backend``; ValueError naming the known ones."""
    try:
        return VENDORS[backend]
    except KeyError:
        raise ValueError(f"unknown backend {backend!r} (known: {', '.join(BACKENDS)})") from None


def model_name_of(backend: str, number: int) -> str | None:
    """The model with this model number on a ``backend`` bus (None: gaitbot does not know it)."""
    for name, known in vendor(backend).MODEL_NUMBERS.items():
        if known == number:
            return name
    return None


def max_servo_id(backend: str, protocol: float) -> int:
    """Highest usable servo id on a ``backend`` bus speaking ``protocol``."""
    return vendor(backend).MAX_ID[float(protocol)]


def has_sync_read(backend: str, protocol: float, byte_order: str) -> bool:
    """Whether the servos answer a SYNC READ (else each one is read on its own)."""
    return vendor(backend).has_sync_read(protocol, byte_order)


def control_table(model_name: str) -> ControlTable:
    """The control table of a servo model, from its vendor's module."""
    for module in VENDORS.values():
        if model_name in module.CONTROL_TABLES:
            return module.CONTROL_TABLES[model_name]
    raise KeyError(f"no control table for servo model {model_name!r}")


def _vendor_of_model(model_name: str) -> ModuleType:
    for module in VENDORS.values():
        if model_name in module.CONTROL_TABLES:
            return module
    raise KeyError(f"no control table for servo model {model_name!r}")


def baud_rates(model_name: str) -> dict[int, int]:
    """Baud Rate register value -> bits per second of a servo model (its vendor's table)."""
    return _vendor_of_model(model_name).BAUD_RATES[model_name]


def baud_register_value(model_name: str, baudrate: int) -> int | None:
    """The Baud Rate register value that sets ``baudrate`` on a model (None: the model cannot run at it)."""
    for value, rate in baud_rates(model_name).items():
        if rate == int(baudrate):
            return value
    return None


def factory_baudrate(model_name: str) -> int:
    """The baud rate a model leaves the factory at (X series 57,600; AX, XL-320 and Feetech 1,000,000)."""
    return baud_rates(model_name)[control_table(model_name)["Baud Rate"].factory]


def common_baud_rates(backend: str, protocol: float, model_names=None) -> tuple[int, ...]:
    """The baud rates worth scanning on a ``backend`` bus speaking ``protocol``: every rate the Baud Rate
    register of a model of that protocol (or of ``model_names``) can hold and the vendor SDK's PortHandler
    accepts (dynamixel_sdk refuses 4.5 M, 400 k, 250 k, 200 k; scservo_sdk 76,800), fastest first."""
    module = vendor(backend)
    from gaitbot.servos.models import SERVO_MODELS  # models is built on this package's tables

    names = model_names or [m.name for m in SERVO_MODELS.values()
                            if m.family == backend and float(protocol) in m.protocols]
    rates = {rate for name in names for rate in baud_rates(name).values() if rate in module.SDK_BAUDRATES}
    return tuple(sorted(rates, reverse=True))


__all__ = ["VENDORS", "BACKENDS", "ASSUMED_RETURN_DELAY_S", "ControlTable", "Register", "RegisterWrite", "vendor",
           "max_servo_id", "has_sync_read", "control_table", "baud_rates", "baud_register_value", "factory_baudrate",
           "common_baud_rates", "dynamixel", "feetech"]
