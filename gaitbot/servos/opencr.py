"""The ROBOTIS OP3's OpenCR sub-controller as a Dynamixel Protocol 2.0 device: its IMU registers.

Facts (no code copied) from ROBOTIS's public sources:

* [FW] ROBOTIS-GIT/OpenCR, arduino/opencr_arduino/opencr/libraries/OP3/examples/opencr_op3/dxl_node_op3.h
  and .cpp (the OP3 firmware): id 200, model number 0x7400, firmware version 2, baud index 3 (2 Mbaud as
  the OP3 manager uses), Return Delay Time 0; its control table (packed, little-endian): Gyro_X/Y/Z int16 at
  32/34/36, Acc_X/Y/Z int16 at 38/40/42, Roll/Pitch/Yaw int16 at 44/46/48 (the fused angles, degrees x 10:
  dxl_hw_op3.cpp), IMU_Control at 50.
* [OM] ROBOTIS-GIT/ROBOTIS-OP3, open_cr_module/src/open_cr_module.cpp: gyro -2000..2000 deg/s over
  -32800..32800 (16.4 LSB per deg/s), accelerometer -2..2 g over -32768..32768 (16384 LSB per g); the board
  sits in the OP3 turned 180 deg about z: robot x and y are the board's -x and -y (z as is).
* ROBOTIS e-Manual, "ROBOTIS OP3 / OpenCR module" (emanual.robotis.com/docs/en/platform/op3/): the OpenCR is
  on the same Dynamixel bus as the servos and provides the gyro and accelerometer.

One READ of IMU_BLOCK (18 bytes) carries every reading: 14 bytes of instruction and 29 of status, 43 bytes
= 430 bits = 0.215 ms on the wire at 2 Mbaud (IMU_READ_WIRE_S), with Return Delay Time 0.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np

from gaitbot.servos.registers import ControlTable, Register

OPENCR_OP3_ID = 200
OPENCR_OP3_MODEL_NUMBER = 0x7400
OPENCR_OP3_FIRMWARE = 2

CONTROL_TABLE: ControlTable = {  # [FW]
    "Model Number": Register(0, 2, OPENCR_OP3_MODEL_NUMBER), "Firmware Version": Register(2, 1, OPENCR_OP3_FIRMWARE),
    "ID": Register(3, 1, OPENCR_OP3_ID), "Baud Rate": Register(4, 1, 3), "Return Delay Time": Register(5, 1, 0),
    "Status Return Level": Register(16, 1, 2), "Roll Offset": Register(18, 2, 0), "Pitch Offset": Register(20, 2, 0),
    "Yaw Offset": Register(22, 2, 0), "Dynamixel Power": Register(24, 1, 0), "LED": Register(25, 1, 0),
    "LED RGB": Register(26, 2, 0x1F), "Buzzer": Register(28, 2, 0), "Button": Register(30, 1, 0),
    "Voltage": Register(31, 1, 120), "Gyro X": Register(32, 2), "Gyro Y": Register(34, 2), "Gyro Z": Register(36, 2),
    "Acc X": Register(38, 2), "Acc Y": Register(40, 2), "Acc Z": Register(42, 2), "Roll": Register(44, 2),
    "Pitch": Register(46, 2), "Yaw": Register(48, 2), "IMU Control": Register(50, 1, 0),
}
TABLE_SIZE = 51
IMU_BLOCK = (CONTROL_TABLE["Gyro X"].address, CONTROL_TABLE["IMU Control"].address - CONTROL_TABLE["Gyro X"].address)
"""(address, length): gyro, accelerometer and fused angles, 18 bytes from address 32."""

GYRO_LSB_PER_DPS = 32800 / 2000  # [OM]: 16.4
ACC_LSB_PER_G = 32768 / 2.0  # [OM]: 16384
ANGLE_LSB_PER_DEG = 10.0  # [FW]
BOARD_TO_ROBOT = np.array([-1.0, -1.0, 1.0])  # [OM]: the board's x and y point backwards and to the right
STANDARD_GRAVITY_M_S2 = 9.80665

PROTOCOL2_READ_BYTES = 14  # header 4, id, length 2, instruction, address 2, data length 2, CRC 2
PROTOCOL2_STATUS_OVERHEAD = 11  # header 4, id, length 2, instruction, error, CRC 2
IMU_READ_WIRE_S = (PROTOCOL2_READ_BYTES + PROTOCOL2_STATUS_OVERHEAD + IMU_BLOCK[1]) * 10 / 2_000_000


@dataclass(frozen=True)
class ImuReading:
    """One OpenCR IMU reading in the robot's frame (x forward, y left, z up): body rates deg/s, specific
    force in g (standing still: +1 g on z), the board's fused roll, pitch, yaw in degrees (its own frame)."""

    gyro_dps: np.ndarray
    acc_g: np.ndarray
    fused_rpy_deg: np.ndarray


def initial_table() -> bytearray:
    """The control table as the firmware starts it (factory values; IMU registers zero)."""
    table = bytearray(TABLE_SIZE)
    for register in CONTROL_TABLE.values():
        if register.factory is not None:
            table[register.address:register.address + register.size] = register.factory.to_bytes(register.size, "little")
    return table


def _int16(values) -> list[int]:
    return [int(max(-32768, min(32767, round(float(v))))) for v in values]


def encode_imu_block(gyro_dps, acc_g, fused_rpy_deg) -> bytes:
    """IMU_BLOCK's bytes for a reading in the robot's frame (the board's mounting applied; clipped to int16)."""
    board_gyro = np.asarray(gyro_dps, dtype=float) * BOARD_TO_ROBOT * GYRO_LSB_PER_DPS
    board_acc = np.asarray(acc_g, dtype=float) * BOARD_TO_ROBOT * ACC_LSB_PER_G
    angles = np.asarray(fused_rpy_deg, dtype=float) * ANGLE_LSB_PER_DEG
    return struct.pack("<9h", *_int16(board_gyro), *_int16(board_acc), *_int16(angles))


def decode_imu_block(data: bytes) -> ImuReading:
    """A reading from IMU_BLOCK's 18 bytes (ValueError for another length)."""
    if len(data) != IMU_BLOCK[1]:
        raise ValueError(f"an OpenCR IMU block is {IMU_BLOCK[1]} bytes, got {len(data)}")
    raw = np.array(struct.unpack("<9h", bytes(data)), dtype=float)
    return ImuReading(raw[0:3] / GYRO_LSB_PER_DPS * BOARD_TO_ROBOT, raw[3:6] / ACC_LSB_PER_G * BOARD_TO_ROBOT,
                      raw[6:9] / ANGLE_LSB_PER_DEG)
