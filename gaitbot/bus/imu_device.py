"""An IMU device for the servo emulator: the OP3's OpenCR at its id, answering READ and PING on the pty.

Its control table is gaitbot.servos.opencr's; its readings follow a scripted motion of the torso (a sway
of ``sway_deg`` at ``sway_hz`` in roll and pitch, the gyro the angles' derivative, the accelerometer gravity
seen from the tilted torso), and from ``fall_at_s`` a fall: the pitch grows at ``fall_rate_dps`` until it lies
flat; from ``drop_at_s`` a drop: the robot falls freely, level, and the accelerometer reads 0 g (the feet's
load lost) with DROP_NOISE_G of noise, as a real one does. ``fault`` (from ``fault_at_s``): "frozen" (the
registers stop changing), "noisy" (100 deg/s of gyro noise) or "absent" (no answer). Kept apart from the
emulator (gaitbot.emulator hands it the packets addressed to its id) so that it can move with the emulator.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass

from gaitbot.servos import opencr, wire

FAULTS = ("frozen", "noisy", "absent")
DROP_NOISE_G = 0.002
"""The accelerometer's noise while it falls freely (1 sigma, g: 300 ug/sqrt(Hz), InvenSense's MPU-9250 product
specification, over the OpenCR's ~40 Hz): 33 LSB, so its registers do not all read 0, which
gaitbot.feel.feedback takes as a dead sensor."""


@dataclass
class ImuDevice:
    """The device; ``answer(frame, now_s)`` is the status packet to send (None: no answer)."""

    device_id: int = opencr.OPENCR_OP3_ID
    sway_deg: float = 2.0
    sway_hz: float = 0.8
    fall_at_s: float | None = None
    fall_rate_dps: float = 120.0
    drop_at_s: float | None = None
    fault: str | None = None
    fault_at_s: float = 1.0
    seed: int = 0

    def __post_init__(self) -> None:
        if self.fault is not None and self.fault not in FAULTS:
            raise ValueError(f"fault must be one of {FAULTS}, got {self.fault!r}")
        self.table = opencr.initial_table()
        self.table[opencr.CONTROL_TABLE["ID"].address] = self.device_id
        self.rng = random.Random(self.seed)

    def motion(self, t_s: float) -> tuple[list[float], list[float], list[float]]:
        """(gyro deg/s, specific force g, roll/pitch/yaw deg) of the scripted torso at ``t_s``."""
        w = 2 * math.pi * self.sway_hz
        roll = self.sway_deg * math.sin(w * t_s)
        pitch = 0.5 * self.sway_deg * math.sin(2 * w * t_s)
        roll_rate, pitch_rate = self.sway_deg * w * math.cos(w * t_s), self.sway_deg * w * math.cos(2 * w * t_s)
        if self.fall_at_s is not None and t_s > self.fall_at_s:
            pitch = min(90.0, pitch + self.fall_rate_dps * (t_s - self.fall_at_s))
            pitch_rate = self.fall_rate_dps if pitch < 90.0 else 0.0
        r, p = math.radians(roll), math.radians(pitch)
        acc = [-math.sin(p), math.cos(p) * math.sin(r), math.cos(p) * math.cos(r)]
        if self.drop_at_s is not None and t_s > self.drop_at_s:
            acc = [0.0, 0.0, 0.0]  # falling freely: nothing but gravity acts, which an accelerometer does not feel
        return [roll_rate, pitch_rate, 0.0], acc, [roll, pitch, 0.0]

    def update(self, now_s: float) -> None:
        """The registers at ``now_s`` (the firmware refreshes them continuously)."""
        faulty = self.fault is not None and now_s >= self.fault_at_s
        if faulty and self.fault == "frozen":
            return
        gyro, acc, rpy = self.motion(now_s)
        if faulty and self.fault == "noisy":
            gyro = [g + self.rng.gauss(0.0, 100.0) for g in gyro]
        if self.drop_at_s is not None and now_s > self.drop_at_s:
            acc = [a + self.rng.gauss(0.0, DROP_NOISE_G) for a in acc]
        start, length = opencr.IMU_BLOCK
        self.table[start:start + length] = opencr.encode_imu_block(gyro, acc, rpy)

    def answer(self, frame: wire.Frame, now_s: float) -> bytes | None:
        """The Protocol 2.0 status packet for a READ or PING addressed to the device (None: none is sent)."""
        if self.fault == "absent" and now_s >= self.fault_at_s:
            return None
        self.update(now_s)
        if frame.instruction == wire.INST_PING:
            params = bytes(self.table[0:2]) + bytes([self.table[opencr.CONTROL_TABLE["Firmware Version"].address]])
        elif frame.instruction == wire.INST_READ:
            address, length, _ = wire.address_length_and_rest(frame.params, "v2")
            if address + length > len(self.table):
                return wire.build_v2(self.device_id, wire.INST_STATUS_V2, bytes([0x05]))  # data range error
            params = bytes(self.table[address:address + length])
        elif frame.instruction == wire.INST_WRITE:
            address, data = wire.address_and_rest(frame.params, "v2")
            self.table[address:address + len(data)] = data
            params = b""
        else:
            return None
        return wire.build_v2(self.device_id, wire.INST_STATUS_V2, bytes([0]) + params)
