"""What a servo's status error byte means, in words, per protocol.

Written from the protocol documents (the same sources as gaitbot.bus.wire):

* Dynamixel Protocol 1.0 (AX, and X series in 1.0 mode) and Feetech: the ERROR byte is a bit field:
  bit 0 input voltage, 1 angle limit, 2 overheating, 3 range, 4 checksum, 5 overload,
  6 instruction (Feetech names bit 1 "angle sensor" and bit 3 "over current"; the SDK's ERRBIT_*).
* Dynamixel Protocol 2.0: bit 7 is the Alert flag (a hardware error; details in the model's
  Hardware Error Status register), bits 0..6 an error number (1 result fail, 2 instruction,
  3 CRC, 4 data range, 5 data length, 6 data limit, 7 access).
  Hardware Error Status bits: X series (address 70) 0 input voltage, 2 overheating, 3 motor
  encoder, 4 electrical shock, 5 overload; XL-320 (address 50) 0 overload, 1 overheating,
  2 input voltage.
"""

from __future__ import annotations

ERRBIT_INPUT_VOLTAGE, ERRBIT_OVERHEATING, ERRBIT_OVERLOAD = 0x01, 0x04, 0x20  # v1 / Feetech bits

V1_ERROR_BITS = {0x01: "input voltage", 0x02: "angle limit", 0x04: "overheating", 0x08: "range", 0x10: "checksum",
                 0x20: "overload", 0x40: "instruction"}
FEETECH_ERROR_BITS = {0x01: "input voltage", 0x02: "angle sensor", 0x04: "overheating", 0x08: "over current",
                      0x20: "overload"}
V2_ALERT = 0x80
V2_ERROR_NUMBERS = {1: "result fail", 2: "instruction error", 3: "CRC error (the servo saw a damaged packet)",
                    4: "data range error", 5: "data length error", 6: "data limit error", 7: "access error"}

#: model name -> (Hardware Error Status address, {bit: meaning}) for Dynamixel Protocol 2.0.
HARDWARE_ERROR_STATUS = {
    "XL430-W250": (70, {0x01: "input voltage", 0x04: "overheating", 0x08: "motor encoder",
                        0x10: "electrical shock", 0x20: "overload"}),
    "XM430-W350": (70, {0x01: "input voltage", 0x04: "overheating", 0x08: "motor encoder",
                        0x10: "electrical shock", 0x20: "overload"}),
    "XL-320": (50, {0x01: "overload", 0x02: "overheating", 0x04: "input voltage"}),
}


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
        if error & V2_ALERT:
            table = HARDWARE_ERROR_STATUS.get(model_name, (None, {}))[1]
            if hardware_error:
                words.extend(_bits(hardware_error, table) if table else [f"hardware error 0x{hardware_error:02X}"])
            else:
                words.append("hardware error (alert)")
        number = error & ~V2_ALERT
        if number:
            words.append(V2_ERROR_NUMBERS.get(number, f"error number {number}"))
        return ", ".join(words) or "no error"
    names = FEETECH_ERROR_BITS if family == "feetech" else V1_ERROR_BITS
    return ", ".join(_bits(error, names)) or "no error"
