"""ROBOTIS Dynamixel facts, from the e-Manual (Protocol 1.0 / 2.0 pages and each model's control table).

Everything gaitbot knows about the vendor is here as data: control tables (register name ->
address, size, factory value), model numbers, the baud rates the SDK accepts, id ranges, the status
error bits. Other rooms read these tables; none writes an address of its own.
"""

from __future__ import annotations

from gaitbot.servos.registers import ControlTable, Register

NAME = "dynamixel"
PROTOCOLS = (1.0, 2.0)
BROADCAST_ID = 0xFE
#: Highest usable id per protocol: 254 is broadcast on both; Protocol 2.0 reserves 253 (0xFD, a header byte).
MAX_ID = {1.0: 253, 2.0: 252}
#: Baud rates dynamixel_sdk's PortHandler accepts, so a dry run refuses what a real run would refuse.
SDK_BAUDRATES = (9600, 19200, 38400, 57600, 115200, 230400, 460800, 500000, 576000, 921600, 1000000,
                 1152000, 2000000, 2500000, 3000000, 3500000, 4000000)
#: Model numbers returned by ping and stored at "Model Number".
MODEL_NUMBERS = {"XL430-W250": 1060, "XM430-W350": 1020, "XL-320": 350, "AX-12A": 12}
#: Firmware version a Protocol 2.0 ping reply carries in the mock chain.
PING_FIRMWARE_VERSION = 45

# X series (XL430-W250, XM430-W350), e-Manual control tables; factory values as shipped.
_X_SERIES: ControlTable = {
    "Model Number": Register(0, 2), "Firmware Version": Register(6, 1, 46), "ID": Register(7, 1),
    "Baud Rate": Register(8, 1, 3), "Return Delay Time": Register(9, 1, 250), "Operating Mode": Register(11, 1, 3),
    "Protocol Type": Register(13, 1, 2), "Temperature Limit": Register(31, 1, 72),
    "Max Voltage Limit": Register(32, 2, 140), "Min Voltage Limit": Register(34, 2, 60),
    "Max Position Limit": Register(48, 4, 4095), "Min Position Limit": Register(52, 4, 0),
    "Shutdown": Register(63, 1, 0x34), "Torque Enable": Register(64, 1), "Status Return Level": Register(68, 1, 2),
    "Hardware Error Status": Register(70, 1), "Position P Gain": Register(84, 2),
    "Profile Velocity": Register(112, 4), "Goal Position": Register(116, 4), "Moving": Register(122, 1),
    "Present Position": Register(132, 4), "Present Input Voltage": Register(144, 2, 120),
    "Present Temperature": Register(146, 1, 30),
}
# Factory Position P Gain: XL430-W250 640 (with Position D Gain 4000), XM430-W350 800.
XL430_W250: ControlTable = {**_X_SERIES, "Position P Gain": Register(84, 2, 640)}
XM430_W350: ControlTable = {**_X_SERIES, "Position P Gain": Register(84, 2, 800)}
XL_320: ControlTable = {
    "Model Number": Register(0, 2), "Firmware Version": Register(2, 1, 30), "ID": Register(3, 1),
    "Baud Rate": Register(4, 1, 3), "Return Delay Time": Register(5, 1, 250), "CCW Angle Limit": Register(8, 2, 1023),
    "Control Mode": Register(11, 1, 2), "Temperature Limit": Register(12, 1, 65),
    "Min Voltage Limit": Register(13, 1, 60), "Max Voltage Limit": Register(14, 1, 90),
    "Max Torque": Register(15, 2, 1023), "Status Return Level": Register(17, 1, 2), "Shutdown": Register(18, 1, 3),
    "Torque Enable": Register(24, 1), "P Gain": Register(29, 1), "Goal Position": Register(30, 2),
    "Moving Speed": Register(32, 2), "Present Position": Register(37, 2), "Present Voltage": Register(45, 1, 74),
    "Present Temperature": Register(46, 1, 30), "Moving": Register(49, 1), "Hardware Error Status": Register(50, 1),
}
AX_12A: ControlTable = {
    "Model Number": Register(0, 2), "Firmware Version": Register(2, 1, 24), "ID": Register(3, 1),
    "Baud Rate": Register(4, 1, 1), "Return Delay Time": Register(5, 1, 250), "CCW Angle Limit": Register(8, 2, 1023),
    "Temperature Limit": Register(11, 1, 70), "Min Voltage Limit": Register(12, 1, 60),
    "Max Voltage Limit": Register(13, 1, 140), "Max Torque": Register(14, 2, 1023),
    "Status Return Level": Register(16, 1, 2), "Alarm LED": Register(17, 1, 0x24), "Shutdown": Register(18, 1, 0x24),
    "Torque Enable": Register(24, 1), "CW Compliance Slope": Register(28, 1, 32),
    "CCW Compliance Slope": Register(29, 1, 32), "Goal Position": Register(30, 2), "Moving Speed": Register(32, 2),
    "Torque Limit": Register(34, 2, 1023), "Present Position": Register(36, 2), "Present Voltage": Register(42, 1, 120),
    "Present Temperature": Register(43, 1, 30), "Moving": Register(46, 1),
}
CONTROL_TABLES = {"XL430-W250": XL430_W250, "XM430-W350": XM430_W350, "XL-320": XL_320, "AX-12A": AX_12A}

# Status packets. Protocol 1.0: the ERROR byte is a bit field. Protocol 2.0: bit 7 is the Alert flag (a
# hardware error; details in the model's Hardware Error Status register), bits 0..6 an error number.
ERRBIT_INPUT_VOLTAGE, ERRBIT_OVERHEATING, ERRBIT_OVERLOAD = 0x01, 0x04, 0x20
V1_ERROR_BITS = {0x01: "input voltage", 0x02: "angle limit", 0x04: "overheating", 0x08: "range", 0x10: "checksum",
                 0x20: "overload", 0x40: "instruction"}
V2_ALERT = 0x80
V2_ERROR_NUMBERS = {1: "result fail", 2: "instruction error", 3: "CRC error (the servo saw a damaged packet)",
                    4: "data range error", 5: "data length error", 6: "data limit error", 7: "access error"}
#: The error a servo answers an instruction it does not know with, per protocol.
INSTRUCTION_ERROR = {1.0: 0x40, 2.0: 0x02}
_X_HARDWARE_ERRORS = {0x01: "input voltage", 0x04: "overheating", 0x08: "motor encoder", 0x10: "electrical shock",
                      0x20: "overload"}
#: Hardware Error Status bits per model (Protocol 2.0; the register's address is in the control table).
HARDWARE_ERROR_BITS = {"XL430-W250": _X_HARDWARE_ERRORS, "XM430-W350": _X_HARDWARE_ERRORS,
                       "XL-320": {0x01: "overload", 0x02: "overheating", 0x04: "input voltage"}}


def has_sync_read(protocol: float, byte_order: str) -> bool:
    """Sync read is a Protocol 2.0 instruction (AX firmware and the SDK's 1.0 handler have none)."""
    return float(protocol) == 2.0
