"""What a servo's status error byte means, in words, per protocol (the bits are the vendors' tables).

* Dynamixel Protocol 1.0 (AX, and X series in 1.0 mode) and Feetech: the ERROR byte is a bit field
  (Feetech names bit 1 "angle sensor" and bit 3 "over current"; the SDKs' ERRBIT_*).
* Dynamixel Protocol 2.0: bit 7 is the Alert flag (a hardware error, whose details are in the model's
  Hardware Error Status register), bits 0..6 an error number.
"""

from __future__ import annotations

from gaitbot.servos import dynamixel, feetech


def hardware_error_address(model_name: str) -> int | None:
    """Address of a Dynamixel 2.0 model's Hardware Error Status register (None: gaitbot knows none)."""
    if model_name not in dynamixel.HARDWARE_ERROR_BITS:
        return None
    return dynamixel.CONTROL_TABLES[model_name]["Hardware Error Status"].address


def hardware_error_bits(model_name: str) -> dict[int, str]:
    """Bit -> fault in words of a model's hardware error register (Dynamixel X and XL-320: Hardware Error
    Status; Feetech: Servo Status); empty when the model has none (AX: errors come in every status)."""
    for module in (dynamixel, feetech):
        if model_name in module.CONTROL_TABLES:
            return dict(module.HARDWARE_ERROR_BITS.get(model_name, {}))
    return {}


def _bits(value: int, names: dict[int, str]) -> list[str]:
    words = [name for bit, name in names.items() if value & bit]
    unknown = value & ~sum(names)
    if unknown:
        words.append(f"unknown bits 0x{unknown:02X}")
    return words


def describe_status_error(family: str, protocol: float, error: int, hardware_error: int | None = None,
                          model_name: str = "") -> str:
    """The error byte of a status packet in words, e.g. ``"overload"`` or ``"input voltage, overheating"``.

    For Dynamixel 2.0, ``hardware_error`` is the Hardware Error Status register when it could be
    read after an Alert; without it the Alert is reported as "hardware error (alert)".
    """
    if family == "dynamixel" and float(protocol) == 2.0:
        words = []
        if error & dynamixel.V2_ALERT:
            table = dynamixel.HARDWARE_ERROR_BITS.get(model_name, {})
            if hardware_error:
                words.extend(_bits(hardware_error, table) if table else [f"hardware error 0x{hardware_error:02X}"])
            else:
                words.append("hardware error (alert)")
        number = error & ~dynamixel.V2_ALERT
        if number:
            words.append(dynamixel.V2_ERROR_NUMBERS.get(number, f"error number {number}"))
        return ", ".join(words) or "no error"
    names = feetech.ERROR_BITS if family == "feetech" else dynamixel.V1_ERROR_BITS
    return ", ".join(_bits(error, names)) or "no error"
