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
#: dynamixel_sdk's PortHandler.clearPort drops pending input (the dry-run port behaves the same).
SDK_CLEAR_PORT_DROPS_INPUT = True
#: Baud rates dynamixel_sdk's PortHandler accepts, so a dry run refuses what a real run would refuse.
SDK_BAUDRATES = (9600, 19200, 38400, 57600, 115200, 230400, 460800, 500000, 576000, 921600, 1000000,
                 1152000, 2000000, 2500000, 3000000, 3500000, 4000000)
#: Protocol -> how servos answer a broadcast ping: Protocol 2.0 servos one after another in id order
#: (e-Manual Protocol 2.0, "Ping"); Protocol 1.0 has no broadcast ping (no status to id 254).
BROADCAST_PING = {2.0: "in turn"}
#: Every Dynamixel stores its words low byte first, so a word read without knowing the model is right.
ONE_BYTE_ORDER = True
#: Model numbers returned by ping and stored at "Model Number".
MODEL_NUMBERS = {"XL430-W250": 1060, "XM430-W350": 1020, "XL-320": 350, "AX-12A": 12}
#: Every Dynamixel leaves the factory at id 1 (e-Manual Protocol 1.0 / 2.0, "ID": "the default ID ... is 1").
FACTORY_ID = 1

# Control tables from the ROBOTIS e-Manual pages "XL430-W250", "XM430-W350", "XL-320" and "AX-12/AX-12A"
# (emanual.robotis.com, section "Control Table"). ``factory`` is the value as shipped
# for settings; for the Present registers it is the value the emulator starts from (not a vendor fact).
# X series (XL430-W250, XM430-W350): EEPROM 0..63, RAM from 64 (EEPROM writable only with torque off).
_X_SERIES: ControlTable = {
    "Model Number": Register(0, 2), "Firmware Version": Register(6, 1, 46), "ID": Register(7, 1, FACTORY_ID),
    # Baud Rate(8): factory 1 = 57,600 bps (e-Manual "Baud Rate(8)", initial value 1)
    "Baud Rate": Register(8, 1, 1), "Return Delay Time": Register(9, 1, 250), "Operating Mode": Register(11, 1, 3),
    "Protocol Type": Register(13, 1, 2), "Temperature Limit": Register(31, 1, 72),
    "Max Voltage Limit": Register(32, 2, 140), "Min Voltage Limit": Register(34, 2, 60),
    "Max Position Limit": Register(48, 4, 4095), "Min Position Limit": Register(52, 4, 0),
    "Shutdown": Register(63, 1, 0x34), "Torque Enable": Register(64, 1), "Status Return Level": Register(68, 1, 2),
    "Hardware Error Status": Register(70, 1), "Position P Gain": Register(84, 2),
    "Profile Velocity": Register(112, 4), "Goal Position": Register(116, 4), "Moving": Register(122, 1),
    # Present Load(126): signed, 0.1 % of the maximum torque, positive = CCW (e-Manual "Present Load(126)")
    "Present Load": Register(126, 2, 0), "Present Position": Register(132, 4),
    "Present Input Voltage": Register(144, 2, 120), "Present Temperature": Register(146, 1, 30),
}
# XL430-W250: Temperature Limit 72 C, voltage limits 14.0 / 6.0 V, Position P Gain 640 (with D 4000).
XL430_W250: ControlTable = {**_X_SERIES, "Position P Gain": Register(84, 2, 640)}
# XM430-W350: Temperature Limit 80 C, voltage limits 16.0 / 9.5 V, Position P Gain 800; address 126 is
# Present Current (2.69 mA a unit), not a load, so it is left out of its table.
XM430_W350: ControlTable = {
    **{name: r for name, r in _X_SERIES.items() if name != "Present Load"},
    "Temperature Limit": Register(31, 1, 80), "Max Voltage Limit": Register(32, 2, 160),
    "Min Voltage Limit": Register(34, 2, 95), "Position P Gain": Register(84, 2, 800)}
# XL-320 (Protocol 2.0 only): EEPROM 0..18, RAM from 24; Present Load(41) bit 10 = direction, 0.1 %.
XL_320: ControlTable = {
    "Model Number": Register(0, 2), "Firmware Version": Register(2, 1, 30), "ID": Register(3, 1, FACTORY_ID),
    "Baud Rate": Register(4, 1, 3), "Return Delay Time": Register(5, 1, 250), "CCW Angle Limit": Register(8, 2, 1023),
    "Control Mode": Register(11, 1, 2), "Temperature Limit": Register(12, 1, 65),
    "Min Voltage Limit": Register(13, 1, 60), "Max Voltage Limit": Register(14, 1, 90),
    "Max Torque": Register(15, 2, 1023), "Status Return Level": Register(17, 1, 2), "Shutdown": Register(18, 1, 3),
    "Torque Enable": Register(24, 1), "P Gain": Register(29, 1), "Goal Position": Register(30, 2),
    "Moving Speed": Register(32, 2), "Present Position": Register(37, 2), "Present Load": Register(41, 2, 0),
    "Present Voltage": Register(45, 1, 74), "Present Temperature": Register(46, 1, 30), "Moving": Register(49, 1),
    "Hardware Error Status": Register(50, 1),
}
# AX-12A (Protocol 1.0): EEPROM 0..18, RAM from 24; no Hardware Error Status register (errors come in every
# status packet's error byte); Present Load(40) bits 0..9 magnitude in 0.1 %, bit 10 = direction (1 = CW).
AX_12A: ControlTable = {
    "Model Number": Register(0, 2), "Firmware Version": Register(2, 1, 24), "ID": Register(3, 1, FACTORY_ID),
    "Baud Rate": Register(4, 1, 1), "Return Delay Time": Register(5, 1, 250), "CCW Angle Limit": Register(8, 2, 1023),
    "Temperature Limit": Register(11, 1, 70), "Min Voltage Limit": Register(12, 1, 60),
    "Max Voltage Limit": Register(13, 1, 140), "Max Torque": Register(14, 2, 1023),
    "Status Return Level": Register(16, 1, 2), "Alarm LED": Register(17, 1, 0x24), "Shutdown": Register(18, 1, 0x24),
    "Torque Enable": Register(24, 1), "CW Compliance Slope": Register(28, 1, 32),
    "CCW Compliance Slope": Register(29, 1, 32), "Goal Position": Register(30, 2), "Moving Speed": Register(32, 2),
    "Torque Limit": Register(34, 2, 1023), "Present Position": Register(36, 2), "Present Load": Register(40, 2, 0),
    "Present Voltage": Register(42, 1, 120), "Present Temperature": Register(43, 1, 30), "Moving": Register(46, 1),
}
CONTROL_TABLES = {"XL430-W250": XL430_W250, "XM430-W350": XM430_W350, "XL-320": XL_320, "AX-12A": AX_12A}
#: First RAM address: registers below it are EEPROM (kept over power-off; with torque on a Protocol 2.0 servo
#: answers a write there with Access Error, e-Manual "Control Table": "Data in the EEPROM Area can only be
#: modified when the value of Torque Enable(64) is set to 0").
EEPROM_END = {"XL430-W250": 64, "XM430-W350": 64, "XL-320": 24, "AX-12A": 24}

_X_BAUD_RATES = {0: 9_600, 1: 57_600, 2: 115_200, 3: 1_000_000, 4: 2_000_000, 5: 3_000_000, 6: 4_000_000,
                 7: 4_500_000}
#: Baud Rate register value -> bits per second, per model. X series: e-Manual "Baud Rate(8)" table (factory 1
#: = 57,600). XL-320: "Baud Rate(4)" 0..3 (factory 3 = 1 Mbps). AX: "Baud Rate(4)": rate = 2,000,000 /
#: (value + 1), the values the e-Manual lists (16 is 117,647 bps for 115,200, -2.1 %; 34 is 57,143 bps for
#: 57,600, +0.8 %: within a UART's tolerance, so the nominal rate is given); factory 1 = 1 Mbps.
BAUD_RATES = {"XL430-W250": _X_BAUD_RATES, "XM430-W350": _X_BAUD_RATES,
              "XL-320": {0: 9_600, 1: 57_600, 2: 115_200, 3: 1_000_000},
              "AX-12A": {1: 1_000_000, 3: 500_000, 4: 400_000, 7: 250_000, 9: 200_000, 16: 115_200, 34: 57_600,
                         103: 19_200, 207: 9_600}}

# Status packets. Protocol 1.0: the ERROR byte is a bit field. Protocol 2.0: bit 7 is the Alert flag (a
# hardware error; details in the model's Hardware Error Status register), bits 0..6 an error number.
ERRBIT_INPUT_VOLTAGE, ERRBIT_OVERHEATING, ERRBIT_OVERLOAD = 0x01, 0x04, 0x20
V1_ERROR_BITS = {0x01: "input voltage", 0x02: "angle limit", 0x04: "overheating", 0x08: "range", 0x10: "checksum",
                 0x20: "overload", 0x40: "instruction"}
V2_ALERT = 0x80
#: Protocol -> the status error bit that means "read the Hardware Error Status register to know more".
ALERT_BITS = {2.0: V2_ALERT}
V2_ERROR_NUMBERS = {1: "result fail", 2: "instruction error", 3: "CRC error (the servo saw a damaged packet)",
                    4: "data range error", 5: "data length error", 6: "data limit error", 7: "access error"}
#: Status Return Level: from this level every instruction gets a status packet, from READS_FROM reads do
#: (a ping always does): 0 ping only, 1 reads too, 2 all (e-Manual, "Status Return Level").
STATUS_RETURN_ALL_FROM, STATUS_RETURN_READS_FROM = 2, 1
#: A REBOOT instruction clears the Hardware Error Status (e-Manual Protocol 2.0, "Reboot").
REBOOT_CLEARS_HARDWARE_ERROR = True
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
