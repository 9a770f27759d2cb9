"""Servo models as data: resolution, range, protocol, byte order and control-table addresses.

Kept as data (the LeRobot habit) so calibration, the bus backends and the emulator read one
table. Addresses come from the vendors' control tables (gaitbot.servos.dynamixel / feetech); each
entry cites its datasheet.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from gaitbot.servos import dynamixel, feetech
from gaitbot.servos.registers import ControlTable, overlaps

#: Laws that turn a gain register value into the position error (deg) at which the loop gives full output.
INVERSE_GAIN = "inverse"  # error_deg = error_deg_times_value / value (a P gain)
COMPLIANCE_SLOPE = "compliance_slope"  # error_deg = representative step (2, 4, ..., 128) x deg_per_unit
SLOPE_STEPS = tuple(2 ** n for n in range(1, 8))  # 2, 4, ..., 128 (e-Manual "Compliance Slope")


@dataclass(frozen=True)
class GainRegister:
    """The control-table register(s) that set how stiff a servo's position loop is, and their scale.

    Every address in ``addresses`` (``length`` bytes each, the model's byte order) gets the same value,
    from ``min_value`` to ``max_value``; ``factory_value`` is what the servo holds after power-on.
    ``law`` says how a value maps to the position error at which the loop gives full output:
    INVERSE_GAIN, error_deg = ``error_deg_times_value`` / value; COMPLIANCE_SLOPE, the value is used as
    its representative step (2, 4, ..., 128) and error_deg = step x ``deg_per_unit``.
    ``before``: (address, length, value, register name) writes that must precede it (Feetech: the
    EEPROM lock on, so that the gain is not saved and lasts until power-off). ``assumed``: the scale
    is not documented by the maker (said so wherever the gain is reported).
    """

    name: str
    addresses: tuple[int, ...]
    length: int
    min_value: int
    max_value: int
    factory_value: int
    law: str
    error_deg_times_value: float = 0.0
    deg_per_unit: float = 0.0
    before: tuple[tuple[int, int, int, str], ...] = ()
    assumed: bool = False
    source: str = ""

    def full_torque_error_deg(self, value: int) -> float:
        """The position error (deg) at which the loop gives full output with ``value`` in the register:
        any byte it may hold (a P gain of 0: infinite, no stiffness; a slope: its step's representative)."""
        if self.law == COMPLIANCE_SLOPE:
            step = min(SLOPE_STEPS[-1], 1 << (max(int(value), SLOPE_STEPS[0]).bit_length() - 1))
            return step * self.deg_per_unit
        if self.law != INVERSE_GAIN:
            raise ValueError(f"unknown gain law {self.law!r}")
        return math.inf if value <= 0 else self.error_deg_times_value / value

    @property
    def factory_error_deg(self) -> float:
        """The stiffness the servo has after power-on (its factory register value), in the same terms."""
        return self.full_torque_error_deg(self.factory_value)


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
    # Drive figures for the simulated robot (gaitbot.sim), each with its source below:
    # stall torque in N m at the voltage of no_load_speed_rpm, and the position error at which the
    # servo's position loop, at its factory gains, asks for full torque (P-only loop: torque grows
    # linearly with the error up to the stall torque).
    stall_torque_nm: float
    full_torque_error_deg: float
    # The register the session writes to set that stiffness (``[servo] full_torque_error_deg``); None
    # when gaitbot knows no register with a usable scale for the model.
    gain: GainRegister | None = None

    def command_register_touched(self, address: int, length: int) -> tuple[int, str] | None:
        """(register address, the bus call to use) when ``length`` bytes at ``address`` touch Goal Position
        (write_goal_ticks) or Torque Enable (set_torque), which are commands, not settings; else None."""
        for start, size, what in ((self.addr_goal_position, self.len_goal_position, "write_goal_ticks"),
                                  (self.addr_torque_enable, 1, "set_torque")):
            if overlaps(address, length, start, size):
                return start, what
        return None

    @property
    def control_table(self) -> ControlTable:
        """The model's whole control table (register name -> address, size, factory value)."""
        return (dynamixel if self.family == "dynamixel" else feetech).CONTROL_TABLES[self.name]

    @property
    def model_number(self) -> int:
        return (dynamixel if self.family == "dynamixel" else feetech).MODEL_NUMBERS[self.name]

    @property
    def ticks_per_rad(self) -> float:
        """Ticks per radian. A full-circle encoder spans range_deg with resolution_ticks steps;
        a 300-degree servo maps 0..max_tick onto 0..range_deg (ROBOTIS AX: 1023 ticks = 300 deg)."""
        span_ticks = self.resolution_ticks if self.wraps else self.max_tick - self.min_tick
        return span_ticks / math.radians(self.range_deg)

    @property
    def no_load_speed_dps(self) -> float:
        return self.no_load_speed_rpm * 6.0

    @property
    def no_load_speed_rad_s(self) -> float:
        return self.no_load_speed_rpm * 2.0 * math.pi / 60.0


# Dynamixel X series in position mode: a PID on the position error in pulses whose output is PWM,
# KPP = Position P Gain / 128, PWM Limit 885 = 100 % (e-Manual "Position PID Gain(84, 82, 80)" and
# "PWM Limit(36)"): the output is full at 885 / KPP pulses = 885 x 128 / gain pulses, so
# error_deg x gain = 885 x 128 x 360 / 4096 = 9956 deg. Factory gains (e-Manual control tables, RAM
# area): XM430-W350 800 -> 141.6 pulses = 12.4 deg; XL430-W250 640 (with Position D Gain 4000) ->
# 177 pulses = 15.6 deg. (MuJoCo Menagerie's ROBOTIS OP3 model gives its XM430 joints kp 21.1 N m/rad
# against a 4.1 N m stall torque: full torque at 11.1 deg, the same order.)
_X_ERROR_DEG_TIMES_GAIN = 885 * 128 * 360 / 4096
_X_FACTORY_GAIN = {name: dynamixel.CONTROL_TABLES[name]["Position P Gain"].factory
                   for name in ("XM430-W350", "XL430-W250")}


def _x_gain(model_name: str) -> GainRegister:
    """Position P Gain(84) of one X series model (only the factory value differs)."""
    register = dynamixel.CONTROL_TABLES[model_name]["Position P Gain"]
    return GainRegister(
        name="Position P Gain", addresses=(register.address,), length=register.size, min_value=1, max_value=16383,
        factory_value=register.factory, law=INVERSE_GAIN, error_deg_times_value=_X_ERROR_DEG_TIMES_GAIN,
        source=f"ROBOTIS e-Manual {model_name} control table: Position P Gain(84), 2 bytes, RAM, 0..16383")


_XL430_GAIN, _XM430_GAIN = _x_gain("XL430-W250"), _x_gain("XM430-W350")

# AX-12A: CW/CCW Compliance Slope (28, 29; 1 byte each, RAM, factory 32; e-Manual AX-12A control table
# and "Compliance Slope"): a value acts as its step's representative 2, 4, 8, 16, 32, 64 or 128, and the
# output falls off over that many units (300/1023 deg each) before the goal: full torque beyond
# 32 x 0.293 = 9.4 deg at the factory slope.
_AX_SLOPES = (dynamixel.AX_12A["CW Compliance Slope"], dynamixel.AX_12A["CCW Compliance Slope"])
_AX_GAIN = GainRegister(
    name="CW/CCW Compliance Slope", addresses=tuple(r.address for r in _AX_SLOPES), length=_AX_SLOPES[0].size,
    min_value=2, max_value=128, factory_value=_AX_SLOPES[0].factory,
    law=COMPLIANCE_SLOPE, deg_per_unit=300 / 1023,
    source="ROBOTIS e-Manual AX-12A control table: CW/CCW Compliance Slope(28, 29), 1 byte each, RAM, "
           "steps 2..128")

# Feetech STS3215: P coefficient (21, 1 byte, factory 32; SMS/STS memory table). Its scale in degrees
# is not documented: ASSUMED to be the X series' at factory gain (full output at 12.4 deg with P = 32)
# and P proportional to 1 / error. Address 21 is in the EEPROM area: with the Lock flag (55, SRAM) at 1
# a write there is not saved and lasts until power-off (Feetech's SCServo library: LockEprom writes 1 to
# address 55, "turn off EPROM saving"; unLockEprom writes 0). Lock is written to 1 first, so the gain
# never outlives a power cycle whatever the servo was left at; that the new P takes effect at once,
# without a restart, is taken from the memory table's RW access and not verified on hardware.
_STS_P, _STS_LOCK = feetech.STS3215["P Coefficient"], feetech.STS3215["Lock"]
_STS_FACTORY_P = _STS_P.factory
_STS_GAIN = GainRegister(
    name="P coefficient", addresses=(_STS_P.address,), length=_STS_P.size, min_value=1, max_value=255,
    factory_value=_STS_FACTORY_P,
    law=INVERSE_GAIN, error_deg_times_value=_STS_FACTORY_P * _X_ERROR_DEG_TIMES_GAIN / _X_FACTORY_GAIN["XM430-W350"],
    before=((_STS_LOCK.address, _STS_LOCK.size, 1, "Lock"),), assumed=True,
    source="Feetech SMS/STS memory table: P coefficient(21), 1 byte, factory 32; Lock(55)")


# Models without a usable gain register keep the X series figure at its factory gain 800 as their
# (assumed) stiffness: the XL-320's P Gain(29) and the SCS0009's P coefficient(21) have no documented
# scale, and the SCS0009's factory value is not known either (the SCS15 manual gives 15, not 32).
_X_FULL_TORQUE_ERROR_DEG = _X_ERROR_DEG_TIMES_GAIN / _X_FACTORY_GAIN["XM430-W350"]


def _addresses(table: ControlTable, velocity: str) -> dict:
    """The ServoModel fields that are control-table addresses, read from the vendor's table."""
    torque, goal, present, speed = (table[name] for name in ("Torque Enable", "Goal Position", "Present Position",
                                                             velocity))
    return dict(addr_torque_enable=torque.address, addr_goal_position=goal.address, len_goal_position=goal.size,
                addr_present_position=present.address, len_present_position=present.size,
                addr_velocity=speed.address, len_velocity=speed.size)


_X_SERIES = dict(
    family="dynamixel", protocols=dynamixel.PROTOCOLS, resolution_ticks=4096, range_deg=360.0, min_tick=0,
    max_tick=4095, centre_tick=2048, wraps=True, byte_order="little",
    **_addresses(dynamixel.XL430_W250, "Profile Velocity"),
)
_AX_TABLE = dict(
    resolution_ticks=1024, range_deg=300.0, min_tick=0, max_tick=1023, centre_tick=512, wraps=False,
    byte_order="little",
)
_FEETECH_TABLE = dict(family="feetech", protocols=feetech.PROTOCOLS, **_addresses(feetech.STS3215, "Goal Speed"))

SERVO_MODELS: dict[str, ServoModel] = {
    m.name: m
    for m in (
        # Verified against emanual.robotis.com/docs/en/dxl/x/xl430-w250/ (ROBOTIS-GIT/emanual,
        # docs/en/dxl/x/xl430-w250.md): model number 1060; Protocol Type (13) selects 1.0 or 2.0;
        # Torque Enable 64 (1 B), Profile Velocity 112 (4 B), Goal Position 116 (4 B, 0..4095 in
        # position mode), Present Position 132 (4 B, signed); 4096 pulse/rev.
        # No-load speed 57 rev/min at 11.1 V (47 at 9 V, 61 at 12 V).
        # Stall torque 1.4 N m at 11.1 V (1.0 at 9 V, 1.5 at 12 V).
        ServoModel(name="XL430-W250", no_load_speed_rpm=57.0, stall_torque_nm=1.4,
                   full_torque_error_deg=_XL430_GAIN.factory_error_deg, gain=_XL430_GAIN,
                   source="ROBOTIS e-Manual XL430-W250 control table and specifications (57 rpm, 1.4 N m @ 11.1 V)",
                   **_X_SERIES),
        # Verified against emanual.robotis.com/docs/en/dxl/x/xm430-w350/: model number 1020; same
        # X-series addresses (64 / 112 / 116 / 132). No-load speed 46 rev/min at 12.0 V (43 @ 11.1 V).
        # Stall torque 4.1 N m at 12 V.
        ServoModel(name="XM430-W350", no_load_speed_rpm=46.0, stall_torque_nm=4.1,
                   full_torque_error_deg=_XM430_GAIN.factory_error_deg, gain=_XM430_GAIN,
                   source="ROBOTIS e-Manual XM430-W350 control table and specifications (46 rpm, 4.1 N m @ 12 V)",
                   **_X_SERIES),
        # Verified against emanual.robotis.com/docs/en/dxl/x/xl320/: Protocol 2.0 only, model 350,
        # joint mode 0..1023 over 300 deg; Torque Enable 24 (1 B), Goal Position 30 (2 B),
        # Moving Speed 32 (2 B), Present Position 37 (2 B). No-load speed 114 rev/min at 7.4 V.
        # Stall torque 0.39 N m at 7.4 V. Its P gain's scale is not documented: the X series figure is assumed.
        ServoModel(name="XL-320", family="dynamixel", protocols=(2.0,), no_load_speed_rpm=114.0, stall_torque_nm=0.39,
                   full_torque_error_deg=_X_FULL_TORQUE_ERROR_DEG,
                   source="ROBOTIS e-Manual XL-320 control table and specifications (114 rpm, 0.39 N m @ 7.4 V)",
                   **_AX_TABLE, **_addresses(dynamixel.XL_320, "Moving Speed")),
        # Verified against emanual.robotis.com/docs/en/dxl/ax/ax-12a/: Protocol 1.0, model 12,
        # 0..1023 over 300 deg (0.29 deg/unit), Torque Enable 24, Goal Position 30 (2 B),
        # Moving Speed 32 (2 B), Present Position 36 (2 B). No-load speed 59 rev/min at 12 V.
        # Stall torque 1.5 N m at 12 V.
        ServoModel(name="AX-12A", family="dynamixel", protocols=(1.0,), no_load_speed_rpm=59.0, stall_torque_nm=1.5,
                   full_torque_error_deg=_AX_GAIN.factory_error_deg, gain=_AX_GAIN,
                   source="ROBOTIS e-Manual AX-12A control table and specifications (59 rpm, 1.5 N m @ 12 V)",
                   **_AX_TABLE, **_addresses(dynamixel.AX_12A, "Moving Speed")),
        # Verified against the Feetech SMS/STS memory table as transcribed in LeRobot
        # (lerobot/motors/feetech/tables.py, STS_SMS_SERIES_CONTROL_TABLE): model number 777 at
        # address 3; Torque Enable 40 (1 B), Goal Position 42 (2 B), Goal Speed 46 (2 B),
        # Present Position 56 (2 B); 4096 steps/rev; STS/SMS store words low byte first (SCS_END 0).
        # No-load speed varies by variant: 0.222 s/60 deg = 45 rpm is the 12 V (C018) figure, the
        # 7.4 V ST3215 is listed at 0.192 s/60 deg = 52 rpm. 45 rpm is kept: the lower figure is the
        # conservative one for speed-limit checks.
        # Stall torque: 19.5 kg cm = 1.9 N m for the 7.4 V ST3215 (30 kg cm at 12 V); the lower figure is
        # kept, like the speed. Its stiffness: _STS_GAIN above (P coefficient, scale assumed).
        ServoModel(name="STS3215", resolution_ticks=4096, range_deg=360.0, min_tick=0, max_tick=4095,
                   centre_tick=2048, wraps=True, byte_order="little", no_load_speed_rpm=45.0,
                   stall_torque_nm=1.9, full_torque_error_deg=_STS_GAIN.factory_error_deg, gain=_STS_GAIN,
                   source="Feetech SMS/STS memory table (via LeRobot tables.py); STS3215 datasheet 45 rpm",
                   **_FEETECH_TABLE),
        # Verified against the Feetech SCSCL memory table (LeRobot SCS_SERIES_CONTROL_TABLE): model 1284,
        # same addresses 40 / 42 / 46 / 56; SCS stores words high byte first (SCS_END 1).
        # SC09/SCS0009 product page: 300 deg over 0..1023 (0.293 deg/step), 0.1 s/60 deg = 100 rpm at 6 V.
        # Stall torque 2.3 kg cm = 0.23 N m at 6 V (SC09 product page); no gain register (see above).
        ServoModel(name="SCS0009", resolution_ticks=1024, range_deg=300.0, min_tick=0, max_tick=1023,
                   centre_tick=512, wraps=False, byte_order="big", no_load_speed_rpm=100.0,
                   stall_torque_nm=0.23, full_torque_error_deg=_X_FULL_TORQUE_ERROR_DEG,
                   source="Feetech SCSCL memory table (via LeRobot tables.py); SC09 spec 100 rpm @ 6 V",
                   **_FEETECH_TABLE),
    )
}


def servo_model(name: str) -> ServoModel:
    """Look a model up by name; KeyError lists the known names."""
    try:
        return SERVO_MODELS[name]
    except KeyError:
        raise KeyError(f"unknown servo model {name!r} (known: {', '.join(sorted(SERVO_MODELS))})") from None
