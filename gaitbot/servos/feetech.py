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
#: scservo_sdk's PortHandler.clearPort only flushes output: pending input stays (the dry-run port behaves the same).
SDK_CLEAR_PORT_DROPS_INPUT = False
#: Baud rates scservo_sdk's PortHandler accepts.
SDK_BAUDRATES = (4800, 9600, 14400, 19200, 38400, 57600, 115200, 128000, 250000, 500000, 1000000)
#: Protocol -> how servos answer a broadcast ping: all at once (Feetech's protocol manual: "cannot be used
#: when multiple servos are connected"), so one clean status packet means one servo and a damaged one several.
BROADCAST_PING = {1.0: "at once"}
#: STS/SMS store words low byte first, SCS high byte first (the Byte Order register says which): a word read
#: without knowing the model needs that register first.
ONE_BYTE_ORDER = False
#: Model numbers stored at "Model Number" (LeRobot's MODEL_NUMBER_TABLE).
MODEL_NUMBERS = {"STS3215": 777, "SCS0009": 1284}

#: Feetech servos leave the factory at id 1 (SMS/STS and SCSCL memory tables, "ID" initial value 1).
FACTORY_ID = 1

# Feetech's "SMS/STS series memory table" (its servo wiki, "Memory table" page; cross-checked with Feetech's
# SMS_STS.h and LeRobot's tables.py): EEPROM 0..39,
# RAM from 40. ``factory`` of a Present register is the emulator's starting value, not a vendor fact.
_SERIES: ControlTable = {
    "Firmware Major Version": Register(0, 1, 3), "Firmware Minor Version": Register(1, 1, 9),
    # Byte Order ("END", 2): 0 = words low byte first (STS/SMS), 1 = high byte first (SCS)
    "Byte Order": Register(2, 1, 0), "Model Number": Register(3, 2), "ID": Register(5, 1, FACTORY_ID), "Baud Rate": Register(6, 1, 0),
    "Return Delay Time": Register(7, 1, 0), "Status Return Level": Register(8, 1, 1),
    "Max Temperature Limit": Register(13, 1, 70), "Min Voltage Limit": Register(15, 1, 40),
    "Max Torque Limit": Register(16, 2, 1000), "P Coefficient": Register(21, 1), "Torque Enable": Register(40, 1),
    "Goal Position": Register(42, 2), "Goal Speed": Register(46, 2),
    # Lock(55): factory 1; 0 = EEPROM writes are saved, 1 = they last until power-off (memory table, "Lock flag")
    "Lock": Register(55, 1, 1),
    "Present Position": Register(56, 2),
    # Present Load(60): bits 0..9 the PWM duty in 0.1 %, bit 10 the direction
    "Present Load": Register(60, 2, 0), "Present Temperature": Register(63, 1, 30),
    # Servo Status(65): the status byte's bits (ERROR_BITS), as a register
    "Servo Status": Register(65, 1, 0), "Moving": Register(66, 1),
}
# Max Voltage Limit: not given by Feetech (the memory table says "-"); 140 (STS) / 80 (SCS) are emulated values.
# The SCS0009's factory P coefficient is not known (the SCS15 manual gives 15), so it is not emulated.
STS3215: ControlTable = {**_SERIES, "P Coefficient": Register(21, 1, 32), "Max Position Limit": Register(11, 2, 4095),
                         "Max Voltage Limit": Register(14, 1, 140), "Present Voltage": Register(62, 1, 74)}
# Feetech's "SCSCL series memory table": the same addresses but the Lock flag at 48, big-endian words.
SCS0009: ControlTable = {**_SERIES, "Max Position Limit": Register(11, 2, 1023),
                         "Max Voltage Limit": Register(14, 1, 80), "Present Voltage": Register(62, 1, 60),
                         "Lock": Register(48, 1, 1), "Byte Order": Register(2, 1, 1)}
CONTROL_TABLES = {"STS3215": STS3215, "SCS0009": SCS0009}
#: First RAM address (memory tables: EEPROM 0..39, SRAM from 40).
EEPROM_END = {"STS3215": 40, "SCS0009": 40}
#: Baud Rate(6) value -> bits per second (Feetech's SMS/STS and SCSCL tables and SMS_STS.h, factory 0 = 1 Mbps;
#: LeRobot's table differs at 5..7 and is not followed: Feetech's own table and SMS_STS.h agree).
_BAUD_RATES = {0: 1_000_000, 1: 500_000, 2: 250_000, 3: 128_000, 4: 115_200, 5: 76_800, 6: 57_600, 7: 38_400}
BAUD_RATES = {"STS3215": _BAUD_RATES, "SCS0009": _BAUD_RATES}

ERRBIT_INPUT_VOLTAGE, ERRBIT_OVERHEATING, ERRBIT_OVERLOAD = 0x01, 0x04, 0x20
ERROR_BITS = {0x01: "input voltage", 0x02: "angle sensor", 0x04: "overheating", 0x08: "over current",
              0x20: "overload"}
#: Model -> the bits of its Servo Status register (the same bits as a status packet's error byte).
HARDWARE_ERROR_BITS = {"STS3215": ERROR_BITS, "SCS0009": ERROR_BITS}
#: Status Return Level ("Response status level"): 0 answers reads (and pings) only, 1 every instruction.
STATUS_RETURN_ALL_FROM, STATUS_RETURN_READS_FROM = 1, 0
#: Feetech documents no reboot clearing its Servo Status.
REBOOT_CLEARS_HARDWARE_ERROR = False
INSTRUCTION_ERROR = {1.0: 0x40}
#: No alert bit: every error is in the status packet's own bits (gaitbot.servos.dynamixel.ALERT_BITS).
ALERT_BITS: dict[float, int] = {}


def has_sync_read(protocol: float, byte_order: str) -> bool:
    """STS/SMS firmware (low byte first) answers SYNC READ (0x82); SCS firmware is read servo by servo
    (Feetech's own SCSCL library offers no sync read for it)."""
    return byte_order == "little"
