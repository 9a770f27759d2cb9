"""Feetech facts, from the SMS/STS and SCSCL memory tables (as transcribed in LeRobot's
``lerobot/motors/feetech/tables.py``) and the SCS protocol manual.

Feetech frames packets like Dynamixel Protocol 1.0 but stores two-byte registers in a per-series
byte order: STS/SMS low byte first, SCS high byte first.
"""

from __future__ import annotations

from gaitbot.servos.registers import ControlTable, Register

NAME = "feetech"
PROTOCOLS = (1.0,)  # the one (Dynamixel-1.0-shaped) protocol Feetech servos speak
BROADCAST_ID = 0xFE
MAX_ID = {1.0: 253}
#: Baud rates scservo_sdk's PortHandler accepts.
SDK_BAUDRATES = (4800, 9600, 14400, 19200, 38400, 57600, 115200, 128000, 250000, 500000, 1000000)
#: Model numbers stored at "Model Number" (LeRobot's MODEL_NUMBER_TABLE).
MODEL_NUMBERS = {"STS3215": 777, "SCS0009": 1284}

_SERIES: ControlTable = {
    "Firmware Major Version": Register(0, 1, 3), "Firmware Minor Version": Register(1, 1, 9),
    "Model Number": Register(3, 2), "ID": Register(5, 1), "Baud Rate": Register(6, 1, 0),
    "Return Delay Time": Register(7, 1, 0), "Status Return Level": Register(8, 1, 1),
    "Max Temperature Limit": Register(13, 1, 70), "Min Voltage Limit": Register(15, 1, 40),
    "Max Torque Limit": Register(16, 2, 1000), "P Coefficient": Register(21, 1), "Torque Enable": Register(40, 1),
    "Goal Position": Register(42, 2), "Goal Speed": Register(46, 2), "Lock": Register(55, 1),
    "Present Position": Register(56, 2), "Present Temperature": Register(63, 1, 30), "Moving": Register(66, 1),
}
# The SCS0009's factory P coefficient is not known (the SCS15 manual gives 15), so it is not emulated.
STS3215: ControlTable = {**_SERIES, "P Coefficient": Register(21, 1, 32), "Max Position Limit": Register(11, 2, 4095),
                         "Max Voltage Limit": Register(14, 1, 140), "Present Voltage": Register(62, 1, 74)}
SCS0009: ControlTable = {**_SERIES, "Max Position Limit": Register(11, 2, 1023),
                         "Max Voltage Limit": Register(14, 1, 80), "Present Voltage": Register(62, 1, 60)}
CONTROL_TABLES = {"STS3215": STS3215, "SCS0009": SCS0009}

ERRBIT_INPUT_VOLTAGE, ERRBIT_OVERHEATING, ERRBIT_OVERLOAD = 0x01, 0x04, 0x20
ERROR_BITS = {0x01: "input voltage", 0x02: "angle sensor", 0x04: "overheating", 0x08: "over current",
              0x20: "overload"}
INSTRUCTION_ERROR = {1.0: 0x40}


def has_sync_read(protocol: float, byte_order: str) -> bool:
    """STS/SMS firmware (low byte first) answers SYNC READ (0x82); SCS firmware is read servo by servo
    (Feetech's own SCSCL library offers no sync read for it)."""
    return byte_order == "little"
