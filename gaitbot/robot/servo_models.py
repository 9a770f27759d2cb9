"""Servo models as data: resolution, range, protocol, byte order and control-table addresses.

Kept as data (the LeRobot habit) so calibration, the bus backends and the emulator read one
table. Each entry cites its datasheet / e-Manual control table.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class ServoModel:
    """One servo model.

    Ticks run from min_tick to max_tick over range_deg; centre_tick is the middle of the travel.
    ``wraps`` is True for servos whose position encoder is a full circle (0 and max are neighbours).
    Addresses are control-table byte addresses; ``*_len`` are sizes in bytes.
    ``byte_order`` is how multi-byte registers are laid out on the wire.
    """

    name: str
    family: str  # "dynamixel" or "feetech"
    protocols: tuple[float, ...]  # Dynamixel protocol versions spoken; (0.0,) style not used for Feetech
    resolution_ticks: int
    range_deg: float
    min_tick: int
    max_tick: int
    centre_tick: int
    wraps: bool
    byte_order: str  # "little" or "big"
    addr_torque_enable: int
    addr_goal_position: int
    len_goal_position: int
    addr_present_position: int
    len_present_position: int
    addr_velocity: int  # profile velocity (Dynamixel X) or moving/goal speed
    len_velocity: int
    no_load_speed_rpm: float
    source: str

    @property
    def ticks_per_rad(self) -> float:
        """Ticks per radian. A full-circle encoder spans range_deg with resolution_ticks steps;
        a 300-degree servo maps 0..max_tick onto 0..range_deg (ROBOTIS AX: 1023 ticks = 300 deg)."""
        span_ticks = self.resolution_ticks if self.wraps else self.max_tick - self.min_tick
        return span_ticks / math.radians(self.range_deg)

    @property
    def no_load_speed_dps(self) -> float:
        return self.no_load_speed_rpm * 6.0


_X_SERIES = dict(
    family="dynamixel", protocols=(1.0, 2.0), resolution_ticks=4096, range_deg=360.0, min_tick=0, max_tick=4095,
    centre_tick=2048, wraps=True, byte_order="little", addr_torque_enable=64, addr_goal_position=116,
    len_goal_position=4, addr_present_position=132, len_present_position=4, addr_velocity=112, len_velocity=4,
)
_AX_TABLE = dict(
    resolution_ticks=1024, range_deg=300.0, min_tick=0, max_tick=1023, centre_tick=512, wraps=False,
    byte_order="little", addr_torque_enable=24, addr_goal_position=30, len_goal_position=2, addr_velocity=32,
    len_velocity=2,
)
_FEETECH_TABLE = dict(
    family="feetech", protocols=(1.0,), addr_torque_enable=40, addr_goal_position=42, len_goal_position=2,
    addr_present_position=56, len_present_position=2, addr_velocity=46, len_velocity=2,
)

SERVO_MODELS: dict[str, ServoModel] = {
    m.name: m
    for m in (
        # e-Manual XL430-W250 control table (Protocol 2.0 firmware; Protocol 1.0 selectable at addr 13).
        # No-load speed 57 rpm at 11.1 V.
        ServoModel(name="XL430-W250", no_load_speed_rpm=57.0,
                   source="ROBOTIS e-Manual, XL430-W250, control table", **_X_SERIES),
        # e-Manual XM430-W350 control table; same X-series layout. No-load speed 46 rpm at 12 V.
        ServoModel(name="XM430-W350", no_load_speed_rpm=46.0,
                   source="ROBOTIS e-Manual, XM430-W350, control table", **_X_SERIES),
        # e-Manual XL-320: Protocol 2.0 only, 0-1023 over 300 deg, goal position 30 (2 B),
        # moving speed 32, present position 37 (2 B). No-load speed 114 rpm at 7.4 V.
        ServoModel(name="XL-320", family="dynamixel", protocols=(2.0,), addr_present_position=37,
                   len_present_position=2, no_load_speed_rpm=114.0,
                   source="ROBOTIS e-Manual, XL-320, control table", **{**_AX_TABLE, "addr_torque_enable": 24}),
        # e-Manual AX-12A: Protocol 1.0, 0-1023 over 300 deg, present position 36 (2 B).
        # No-load speed 59 rpm at 12 V.
        ServoModel(name="AX-12A", family="dynamixel", protocols=(1.0,), addr_present_position=36,
                   len_present_position=2, no_load_speed_rpm=59.0,
                   source="ROBOTIS e-Manual, AX-12/AX-12A, control table", **_AX_TABLE),
        # Feetech STS3215 memory table (SMS/STS series, low byte first): 4096 ticks over 360 deg.
        # 0.222 s/60 deg at 7.4 V, about 45 rpm.
        ServoModel(name="STS3215", resolution_ticks=4096, range_deg=360.0, min_tick=0, max_tick=4095,
                   centre_tick=2048, wraps=True, byte_order="little", no_load_speed_rpm=45.0,
                   source="Feetech STS3215 datasheet and SMS/STS memory table", **_FEETECH_TABLE),
        # Feetech SCS0009 memory table (SCS series, high byte first): 1024 ticks over 300 deg.
        # 0.1 s/60 deg at 6 V, about 100 rpm.
        ServoModel(name="SCS0009", resolution_ticks=1024, range_deg=300.0, min_tick=0, max_tick=1023,
                   centre_tick=512, wraps=False, byte_order="big", no_load_speed_rpm=100.0,
                   source="Feetech SCS0009 datasheet and SCS memory table", **_FEETECH_TABLE),
    )
}


def servo_model(name: str) -> ServoModel:
    """Look a model up by name; KeyError lists the known names."""
    try:
        return SERVO_MODELS[name]
    except KeyError:
        raise KeyError(f"unknown servo model {name!r} (known: {', '.join(sorted(SERVO_MODELS))})") from None
