"""Robot description from a TOML file: geometry, gait settings, bus and joints, validated.

Why so strict: a config error found on the bench means a servo driven into its end stop or a
mirror-mounted knee bending backwards. Every value is checked when the file is loaded (through
gaitbot.fields, the one field-checked reader) and the first problem is reported as ONE line naming
the file, the field and what is allowed::

    config/xl430-biped.toml: joints.knee_pitch_left.min_deg: 120.0 is above max_deg 110.0

The file format is written down in docs/robot-config.md.

The data classes are in gaitbot.robot.config_types (their fields are the tables' keys), finding the
shipped robots and ConfigError in gaitbot.robot.shipped_configs; both are re-exported here.

Whether the bus can carry ``gait.rate_hz`` frames at ``bus.baudrate`` is checked on load too, with the
frame-budget arithmetic of the vendor facts (gaitbot.servos.budget): loading a robot runs no bus code.
"""

from __future__ import annotations

import difflib
import math
from pathlib import Path
from typing import Any

import numpy as np

from gaitbot.fields import Fields, kind, read_toml
from gaitbot.gait.balance.settings import LIMITS as BALANCE_LIMITS
from gaitbot.gait.balance.settings import BalanceSettings
from gaitbot.gait.body import LEG_LINKS, LinkInertial, inertia_matrix
from gaitbot.gait.geometry import LegGeometry
from gaitbot.gait.joints import LEG_JOINTS, PITCH_JOINTS, PITCH_KINDS, canonical, is_leg_joint, mirror, split_joint
from gaitbot.gait.walker import WalkSettings, make_context
from gaitbot.robot.calibration import angle_rad_to_ticks
from gaitbot.robot.config_types import (TORSO_HEIGHT_LEGS, BusSettings, GaitSettings, Geometry,  # noqa: F401
                                        JointConfig, MassSettings, RobotConfig, ServoSettings, TerrainReach,
                                        field_names)
from gaitbot.robot.gains import GainError, gain_for_error
from gaitbot.robot.health import read_health
from gaitbot.robot.shipped_configs import (DEFAULT_ROBOT, ConfigError, default_config_path,  # noqa: F401
                                           resolve_config, shipped_config_dirs, shipped_config_names)
from gaitbot.robot.imu_settings import read_imu
from gaitbot.robot.steer_settings import read_steer
from gaitbot.servos import BACKENDS, baud_rates, feetech, max_servo_id, vendor
from gaitbot.servos.budget import FrameBudget, check_rate
from gaitbot.servos.models import SERVO_MODELS, ServoModel



# ---------------------------------------------------------------------------------------------
# Loading


def load_robot_config(path: str | Path) -> RobotConfig:
    """Read and validate a robot config; raise ConfigError (one line) on the first problem, including a
    ``gait.rate_hz`` its bus cannot carry (:func:`check_bus_rate`)."""
    path = Path(path)
    data = read_toml(path, ConfigError)
    config = _Reader(path).robot(data)
    try:
        check_bus_rate(config, config.gait.rate_hz)
    except ValueError as exc:
        raise ConfigError(config.path, "gait.rate_hz", str(exc)) from None
    return config


def check_bus_rate(config: RobotConfig, rate_hz: float) -> FrameBudget:
    """ValueError if ``config``'s bus cannot carry ``rate_hz`` frames per second with the read-back every
    session makes (goal writes plus one servo's read, with margin: gaitbot.servos.budget.check_rate)."""
    return check_rate(rate_hz, config.bus.backend, config.bus.protocol, config.joints[0].model, len(config.joints),
                      config.bus.baudrate, read_back=True)


#: Where a robot whose legs roll may have its ankle axis along (and across) its sole, as fractions of the sole's
#: length from the heel (and of its width about its centre): its middle half. The shipped robots have theirs
#: at the middle (op3, bioloid); a hand-written 12-joint config with the ankle at the heel planned walks that
#: lifted both feet.
SOLE_MIDDLE = (0.25, 0.75)

#: Bounds of every size a config can ask for (value ranges, both ends included; the shipped robots sit
#: well inside them). Beyond them a field is refused on load, before any work: a cycle of 1e9 s or a
#: step of 1e-9 m would otherwise ask for gigabytes of frames (docs/robot-config.md).
LIMB_RANGE_M = (0.0, 2.0, "m")
CYCLE_RANGE_S = (0.2, 10.0, "s")
STEP_RANGE_M = (0.005, 2.0, "m")
CLEARANCE_RANGE_M = (0.0, 0.5, "m")
#: Frame rates a walk may stream at: below 10 Hz each goal is a jump a position servo makes at full
#: speed; above 200 Hz no read-back fits in a frame (gaitbot.stream.readback).
RATE_RANGE_HZ = (10.0, 200.0, "Hz")
ANGLE_RANGE_DEG = (-360.0, 360.0, "deg")
VELOCITY_RANGE_DPS = (0.0, 100_000.0, "deg/s")
ACCELERATION_RANGE_DPS2 = (0.0, 10_000_000.0, "deg/s^2")
MASS_RANGE_KG = (0.0, 1000.0, "kg")
#: The swing foot's clearance may be at most this share of the leg (thigh + shank).
CLEARANCE_SHARE_OF_LEG = 0.25

MASS_TOLERANCE_KG = 1e-4
"""``[mass] total_kg`` must equal the links' sum within this (0.1 g: the files hold 6 digits)."""

_TOP_KEYS = ("robot", "geometry", "gait", "bus", "joints", "mass", "servo", "terrain", "health", "balance", "links",
             "steer", "imu", "feedback", "fall")
# Each table's allowed keys are its data class's fields (gaitbot.robot.config_types): written once.
_MASS_KEYS = field_names(MassSettings) + ("total_kg",)
_LINK_NAMES = ("torso",) + LEG_LINKS
_LINK_KEYS = field_names(LinkInertial)
_SERVO_KEYS = field_names(ServoSettings)
_TERRAIN_KEYS = field_names(TerrainReach)
_ROBOT_KEYS = ("name", "boom", "draft")
_GEOMETRY_KEYS = field_names(Geometry)
_GAIT_KEYS = field_names(GaitSettings)
_BUS_KEYS = field_names(BusSettings)
_JOINT_KEYS = field_names(JointConfig, without=("name",))


class _Reader(Fields):
    """The robot config's sections, read field by field (gaitbot.fields)."""

    def __init__(self, path: Path) -> None:
        super().__init__(path, ConfigError)

    # -- sections -----------------------------------------------------------------------------

    def robot(self, data: dict) -> RobotConfig:
        self.no_unknown_keys(data, "", _TOP_KEYS)
        robot = self.table(data, "robot", "robot", _ROBOT_KEYS)
        name = self.string(robot, "name", "robot")
        geometry = self.geometry(self.table(data, "geometry", "geometry", _GEOMETRY_KEYS))
        gait = self.gait(self.table(data, "gait", "gait", _GAIT_KEYS))
        bus = self.bus(self.table(data, "bus", "bus", _BUS_KEYS))
        joints = self.joints(data, bus)
        boom = self.boolean(robot, "boom", "robot", default=False)
        draft = self.string(robot, "draft", "robot") if "draft" in robot else None
        links = self.links(data, geometry) if "links" in data else None
        mass = self.mass(self.optional_table(data, "mass", "mass", _MASS_KEYS), links)
        servo = self.servo(self.optional_table(data, "servo", "servo", _SERVO_KEYS))
        self.gains_settable(joints, servo)
        self.walkable(geometry, gait)
        terrain = None
        if "terrain" in data:
            t = self.table(data, "terrain", "terrain", _TERRAIN_KEYS)
            terrain = TerrainReach(*(self.number(t, key, "terrain", non_negative=True, within=LIMB_RANGE_M)
                                     for key in _TERRAIN_KEYS))
        health = read_health(self, data, joints)
        balance = self.balance(self.optional_table(data, "balance", "balance", BalanceSettings.field_names()))
        config = RobotConfig(path=self.path, name=name, geometry=geometry, gait=gait, bus=bus, joints=joints,
                             mass=mass, servo=servo, terrain=terrain, health=health, balance=balance, links=links,
                             boom=boom, draft=draft, steer=read_steer(self, data), imu=read_imu(self, data, bus))
        self.three_d_checks(config)
        self.soles_stand(config, data["geometry"])
        return config

    def walkable(self, geometry: Geometry, gait: GaitSettings) -> None:
        """Sizes that only make sense together: the swing clearance against the leg, the longest step
        against what the leg reaches in its cycle (refused, not silently clipped)."""
        leg_m = geometry.thigh_m + geometry.shank_m
        if gait.clearance_m > CLEARANCE_SHARE_OF_LEG * leg_m:
            raise self.fail("gait.clearance_m", f"{gait.clearance_m:g} m is more than "
                                                f"{CLEARANCE_SHARE_OF_LEG:g} of the leg (thigh_m + shank_m = "
                                                f"{leg_m:g} m): at most {CLEARANCE_SHARE_OF_LEG * leg_m:.3g} m")
        leg = LegGeometry(thigh=geometry.thigh_m, shank=geometry.shank_m, foot=geometry.foot_m,
                          hip_width=geometry.hip_width_m, ankle_height=geometry.ankle_height_m,
                          heel_back=geometry.heel_back_m)
        try:
            reach_m = make_context(leg, WalkSettings(gait.cycle_s, gait.rate_hz, gait.clearance_m)).inverse.max_step_length
        except (ValueError, ArithmeticError) as exc:
            raise self.fail("geometry", f"this leg cannot walk with cycle_s {gait.cycle_s:g} s ({exc})") from None
        if gait.max_step_m > reach_m * (1 + 1e-9):
            raise self.fail("gait.max_step_m", f"{gait.max_step_m:g} m is longer than this leg reaches in a "
                                               f"{gait.cycle_s:g} s cycle ({reach_m:.4g} m); at most {reach_m:.4g} m")

    def mass(self, t: dict, links) -> MassSettings:
        """The four planar segments, or with ``[links.*]`` only ``total_kg``, which must add up."""
        if links is not None:
            for key in _MASS_KEYS[:4]:
                if key in t:
                    raise self.fail(f"mass.{key}", "give link masses in [links.*] or segment masses in [mass], "
                                                   "not both")
            total = self.number(t, "total_kg", "mass", positive=True, within=MASS_RANGE_KG)
            summed = sum(link.mass_kg * (1 if name == "torso" else 2) for name, link in links)
            if abs(summed - total) > MASS_TOLERANCE_KG:
                raise self.fail("mass.total_kg", f"{total:g} kg, but torso + 2 x the leg links add up to "
                                                 f"{summed:.6f} kg (a mass table that does not add up)")
            return MassSettings()
        defaults = MassSettings()
        mass = MassSettings(**{k: self.number(t, k, "mass", positive=True, default=getattr(defaults, k),
                                              within=MASS_RANGE_KG)
                               for k in _MASS_KEYS[:4]})
        if "total_kg" in t:
            total = self.number(t, "total_kg", "mass", positive=True)
            if abs(mass.total_kg - total) > MASS_TOLERANCE_KG:
                raise self.fail("mass.total_kg", f"{total:g} kg, but torso_kg + 2 x (thigh_kg + shank_kg + foot_kg) "
                                                 f"= {mass.total_kg:.6f} kg")
        return mass

    def links(self, data: dict, geometry: Geometry) -> tuple[tuple[str, LinkInertial], ...]:
        """``[links.<name>]``: mass, centre of mass and inertia of the torso and the left leg's six links.

        Physical ranges: a link's centre of mass lies within the robot's reach of its joint (the leg, thigh +
        shank + foot: no link of a biped is larger), and its inertia is a rigid body's: principal moments
        positive (zero for a massless link), none larger than the other two together, and none larger than
        mass x reach^2 (all of a link's mass within the reach of its centre)."""
        tables = self.table(data, "links", "links", _LINK_NAMES)
        reach_m = geometry.thigh_m + geometry.shank_m + geometry.foot_m
        out = []
        for name in _LINK_NAMES:
            f = f"links.{name}"
            t = self.table(tables, name, f, _LINK_KEYS)
            mass = self.number(t, "mass_kg", f, positive=name == "torso", non_negative=True, within=MASS_RANGE_KG)
            com = self.vector(t, "com_m", f, 3, "[x, y, z] in metres")
            distance_m = math.sqrt(sum(c * c for c in com)) if all(abs(c) < 1e100 for c in com) else math.inf
            if distance_m > reach_m:
                raise self.fail(f"{f}.com_m", f"{distance_m:.3g} m from the link's joint, beyond the robot's reach "
                                              f"(thigh_m + shank_m + foot_m = {reach_m:g} m)")
            values = self.vector(t, "inertia_kg_m2", f, 6, "[Ixx, Iyy, Izz, Ixy, Ixz, Iyz] in kg m^2")
            largest = mass * reach_m ** 2
            for i, value in enumerate(values):
                if not abs(value) <= largest:
                    raise self.fail(f"{f}.inertia_kg_m2[{i}]", f"{value:g} kg m^2 is more than a {mass:g} kg link within "
                                                               f"the robot's reach can have (mass_kg x {reach_m:g}^2 = "
                                                               f"{largest:.3g} kg m^2)")
            inertia = inertia_matrix(*values)
            moments = np.linalg.eigvalsh(inertia)
            scale = max(float(moments.max()), 1e-12)
            positive = moments.min() > 0 if mass > 0 else moments.min() >= -1e-9 * scale
            if not positive or moments.max() > moments.sum() - moments.max() + 1e-9 * scale:
                raise self.fail(f"{f}.inertia_kg_m2", "is not the inertia of a rigid body (its principal moments "
                                                      f"{', '.join(f'{m:.3g}' for m in moments)} must be > 0 and "
                                                      "none larger than the other two together)")
            out.append((name, LinkInertial(mass, np.array(com), inertia)))
        return tuple(out)

    def vector(self, t: dict, key: str, f: str, length: int, what: str) -> list[float]:
        value = self.require(t, key, f, what)
        if not isinstance(value, list) or len(value) != length:
            raise self.fail(f"{f}.{key}", f"must be {what}, got {kind(value)}")
        return [self.check_number(v, f"{f}.{key}[{i}]") for i, v in enumerate(value)]

    def balance(self, t: dict) -> BalanceSettings:
        values = {}
        for key in t:
            if key == "sag_feedforward":
                values[key] = self.boolean(t, key, "balance", default=True)
                continue
            lo, hi = BALANCE_LIMITS[key]
            value = self.number(t, key, "balance")
            if not lo <= value <= hi:
                raise self.fail(f"balance.{key}", f"{value:g} is outside {lo:g}..{hi:g}")
            values[key] = value
        return BalanceSettings(**values)

    def three_d_checks(self, config: RobotConfig) -> None:
        """A robot whose legs roll needs a sole width, and roll limits that can keep its soles flat."""
        if not config.is_3d:
            return
        if config.geometry.foot_width_m is None:
            raise self.fail("geometry.foot_width_m", "missing (a robot with hip and ankle roll joints balances "
                                                     "sideways on its soles: give their width in metres)")
        g = config.geometry
        needed = math.degrees(math.atan2(g.hip_width_m / 2 + g.sole_outward_m, g.thigh_m + g.shank_m))
        for side in ("left", "right"):
            hip, ankle = config.joint(f"hip_roll_{side}"), config.joint(f"ankle_roll_{side}")
            # a flat sole under an upright torso has ankle_roll = -hip_roll
            lo, hi = max(hip.min_deg, -ankle.max_deg), min(hip.max_deg, -ankle.min_deg)
            if lo > -needed or hi < needed:
                raise self.fail(f"joints.ankle_roll_{side}.min_deg" if hi < needed else f"joints.ankle_roll_{side}.max_deg",
                                f"a flat sole needs ankle_roll = -hip_roll; to bring the body over one foot the hip "
                                f"rolls {needed:.1f} deg either way, but with these limits the soles stay flat only "
                                f"for hip_roll {lo:.1f}..{hi:.1f} deg")

    def soles_stand(self, config: RobotConfig, given: dict) -> None:
        """A robot whose legs roll balances on its soles: it needs the heel's place said, not defaulted, and
        each ankle over the middle half of its sole (SOLE_MIDDLE), or its balance point has no sole around it
        and the walk it plans lifts both feet ("no sole touches the ground") or tips."""
        if not config.is_3d:
            return
        g = config.geometry
        lo, hi = SOLE_MIDDLE[0] * g.foot_m, SOLE_MIDDLE[1] * g.foot_m
        where = (f"the ankle axis must stand over the middle half of the sole: {lo:.4g}..{hi:.4g} m for "
                 f"foot_m {g.foot_m:g}")
        if "heel_back_m" not in given:
            raise self.fail("geometry.heel_back_m", f"missing (a robot whose legs roll stands on its soles: give "
                                                    f"how far the heel reaches behind the ankle axis, metres; {where})")
        if not lo <= g.heel_back_m <= hi:
            raise self.fail("geometry.heel_back_m", f"{g.heel_back_m:g} m puts the ankle too near the "
                                                    f"{'heel' if g.heel_back_m < lo else 'toe'}: {where}")
        side = SOLE_MIDDLE[1] - 0.5
        if abs(g.sole_outward_m) > side * g.foot_width_m:
            raise self.fail("geometry.sole_outward_m", f"{g.sole_outward_m:g} m: the ankle must stand over the middle "
                                                       f"half of the sole's width, within +-{side * g.foot_width_m:.4g} "
                                                       f"m for foot_width_m {g.foot_width_m:g}")

    def servo(self, t: dict) -> ServoSettings:
        return ServoSettings(**{k: self.number(t, k, "servo", positive=True) if k in t else None
                                for k in _SERVO_KEYS})

    def gains_settable(self, joints: tuple[JointConfig, ...], servo: ServoSettings) -> None:
        """A stiffness asked for must be one every servo's gain register can hold (it is written to all)."""
        if servo.full_torque_error_deg is None:
            return
        for joint in joints:
            try:
                gain_for_error(joint.model, servo.full_torque_error_deg)
            except GainError as exc:
                where = f"joints.{joint.name} ({joint.model.name})"
                raise self.fail("servo.full_torque_error_deg", f"{where}: {exc}") from None

    def geometry(self, t: dict) -> Geometry:
        f = "geometry"
        length = LIMB_RANGE_M
        geometry = Geometry(
            thigh_m=self.number(t, "thigh_m", f, positive=True, within=length),
            shank_m=self.number(t, "shank_m", f, positive=True, within=length),
            foot_m=self.number(t, "foot_m", f, positive=True, within=length),
            hip_width_m=self.number(t, "hip_width_m", f, positive=True, within=length),
            ankle_height_m=self.number(t, "ankle_height_m", f, non_negative=True, default=0.0, within=length),
            heel_back_m=self.number(t, "heel_back_m", f, non_negative=True, default=0.0, within=length),
            foot_width_m=self.number(t, "foot_width_m", f, positive=True, within=length) if "foot_width_m" in t else None,
            sole_outward_m=self.number(t, "sole_outward_m", f, default=0.0, within=(-1.0, 1.0, "m")),
            hip_below_root_m=self.number(t, "hip_below_root_m", f, non_negative=True, default=0.0, within=length),
        )
        if geometry.foot_width_m is not None and geometry.foot_width_m <= 0:
            raise self.fail("geometry.foot_width_m", f"must be a positive number, got {geometry.foot_width_m}")
        if geometry.heel_back_m >= geometry.foot_m:
            raise self.fail("geometry.heel_back_m", f"{geometry.heel_back_m} must be shorter than foot_m "
                                                    f"{geometry.foot_m} (the heel is behind the ankle, the toe ahead)")
        leg_m = geometry.thigh_m + geometry.shank_m
        for key in ("foot_m", "ankle_height_m", "hip_width_m"):
            value = getattr(geometry, key)
            if value > leg_m:
                raise self.fail(f"geometry.{key}", f"{value:g} m is longer than the leg (thigh_m + shank_m = "
                                                   f"{leg_m:g} m); at most {leg_m:g} m")
        return geometry

    def gait(self, t: dict) -> GaitSettings:
        f = "gait"
        return GaitSettings(
            cycle_s=self.number(t, "cycle_s", f, positive=True, within=CYCLE_RANGE_S),
            max_step_m=self.number(t, "max_step_m", f, positive=True, within=STEP_RANGE_M),
            clearance_m=self.number(t, "clearance_m", f, positive=True, within=CLEARANCE_RANGE_M),
            rate_hz=self.number(t, "rate_hz", f, positive=True, within=RATE_RANGE_HZ),
        )

    def bus(self, t: dict) -> BusSettings:
        f = "bus"
        backend = self.string(t, "backend", f, f"one of {', '.join(map(repr, BACKENDS))}")
        if backend not in BACKENDS:
            raise self.fail("bus.backend", f"unknown backend {backend!r} (allowed: {', '.join(BACKENDS)})")
        protocols = vendor(backend).PROTOCOLS
        protocol = protocols[0]
        if len(protocols) > 1:
            allowed = " or ".join(str(p) for p in protocols)
            protocol = self.number(t, "protocol", f)
            if protocol not in protocols:
                raise self.fail("bus.protocol", f"unknown {backend.capitalize()} protocol {protocol} (allowed: {allowed})")
        # A vendor whose servos speak one protocol (Feetech): a protocol key is accepted and ignored (always 1.0).
        port = self.string(t, "port", f, "a serial port name, e.g. '/dev/ttyUSB0' or 'COM3'")
        rates = vendor(backend).SDK_BAUDRATES
        allowed_rates = ", ".join(str(r) for r in rates)
        baudrate = self.integer(t, "baudrate", f, f"a baud rate the {backend} SDK sets: {allowed_rates}")
        if baudrate not in rates:
            raise self.fail("bus.baudrate", f"{baudrate} is not a baud rate the {backend} SDK can set "
                                            f"(allowed: {allowed_rates})")
        torque_off = self.boolean(t, "torque_off_on_exit", f, default=False)
        return BusSettings(backend=backend, protocol=protocol, port=port, baudrate=baudrate,
                           torque_off_on_exit=torque_off)

    def joints(self, data: dict, bus: BusSettings) -> tuple[JointConfig, ...]:
        """Any mirrored set of leg joints that includes both legs' pitch joints; the moving ones first."""
        if "joints" not in data:
            raise self.fail("joints", f"missing section (expected [joints.<name>] for at least {', '.join(PITCH_JOINTS)})")
        tables = data["joints"]
        if not isinstance(tables, dict):
            raise self.fail("joints", f"must be tables [joints.<name>], got {kind(tables)}")
        for name in PITCH_JOINTS:
            if name not in tables:
                others = [n for n in tables if not is_leg_joint(n)]
                close = difflib.get_close_matches(name, others, n=1)
                hint = f"; is {close[0]!r} a typo of it?" if close else ""
                raise self.fail(f"joints.{name}", f"missing walking joint (all of {', '.join(PITCH_JOINTS)} "
                                                  f"are required{hint})")
        for name in tables:
            if not is_leg_joint(name):
                close = difflib.get_close_matches(name, LEG_JOINTS, n=1)
                hint = f"did you mean {close[0]!r}? " if close else ""
                raise self.fail(f"joints.{name}", f"unknown joint ({hint}allowed: {', '.join(LEG_JOINTS)})")
        for name in canonical(tables):
            if mirror(name) not in tables:
                raise self.fail(f"joints.{mirror(name)}", f"missing: joints.{name} has no mirror on the other leg "
                                                          f"(both legs must have the same joints)")
        joints = {name: self.joint(name, tables[name], bus) for name in canonical(tables)}
        for name, joint in joints.items():
            other = joints[mirror(name)]
            if joint.hold_deg is None and other.hold_deg is not None:
                raise self.fail(f"joints.{name}.hold_deg", f"missing: joints.{other.name} is held at "
                                                           f"{other.hold_deg:g} deg, so its mirror must be held too "
                                                           f"(or remove hold_deg from both to walk with them)")
        moving = [j for j in joints.values() if j.hold_deg is None]
        held = [j for j in joints.values() if j.hold_deg is not None]
        ordered = tuple(moving + held)
        self.bus_wide_checks(ordered, bus)
        return ordered

    def joint(self, name: str, t: Any, bus: BusSettings) -> JointConfig:
        f = f"joints.{name}"
        if not isinstance(t, dict):
            raise self.fail(f, f"must be a table [{f}], got {kind(t)}")
        self.no_unknown_keys(t, f, _JOINT_KEYS)
        walking = split_joint(name)[0] in PITCH_KINDS

        model_name = self.string(t, "model", f, f"a servo model ({', '.join(SERVO_MODELS)})")
        if model_name not in SERVO_MODELS:
            raise self.fail(f"{f}.model", f"unknown servo model {model_name!r} (allowed: {', '.join(SERVO_MODELS)})")
        model = SERVO_MODELS[model_name]
        if model.family != bus.backend:
            fitting = [m.name for m in SERVO_MODELS.values() if m.family == bus.backend]
            raise self.fail(f"{f}.model", f"{model_name} is a {model.family} servo but bus.backend is "
                                          f"{bus.backend!r} (allowed: {', '.join(fitting)})")
        if bus.protocol not in model.protocols:
            spoken = ", ".join(str(p) for p in model.protocols)
            raise self.fail("bus.protocol", f"{model_name} ({f}) does not speak protocol {bus.protocol} "
                                            f"(it speaks {spoken})")

        rates = sorted(set(baud_rates(model_name).values()), reverse=True)
        if bus.baudrate not in rates:  # the model's Baud Rate register (ROBOTIS e-Manual, Feetech's memory table)
            raise self.fail("bus.baudrate", f"a {model_name} ({name}) cannot run at {bus.baudrate:,} baud (its Baud "
                                            f"Rate register allows: {', '.join(map(str, rates))})")

        max_id = max_servo_id(bus.backend, bus.protocol)
        servo_id = self.integer(t, "id", f, f"an integer servo id 0..{max_id}")
        if not 0 <= servo_id <= max_id:
            raise self.fail(f"{f}.id", f"{servo_id} is out of range for {bus.backend} (allowed: 0..{max_id})")

        zero_tick = self.integer(t, "zero_tick", f, f"an integer tick {model.min_tick}..{model.max_tick}")
        if not model.min_tick <= zero_tick <= model.max_tick:
            raise self.fail(f"{f}.zero_tick", f"{zero_tick} is outside the {model_name}'s tick range "
                                              f"{model.min_tick}..{model.max_tick}")
        direction = self.integer(t, "direction", f, "1 or -1")
        if direction not in (1, -1):
            raise self.fail(f"{f}.direction", f"must be 1 or -1 (-1 for a mirror-mounted servo), got {direction}")

        min_deg = self.number(t, "min_deg", f, within=ANGLE_RANGE_DEG)
        max_deg = self.number(t, "max_deg", f, within=ANGLE_RANGE_DEG)
        if min_deg > max_deg:
            raise self.fail(f"{f}.min_deg", f"{min_deg} is above max_deg {max_deg}")
        for key, angle_deg in (("min_deg", min_deg), ("max_deg", max_deg)):
            problem = angle_outside_servo(model, zero_tick, direction, angle_deg)
            if problem:
                raise self.fail(f"{f}.{key}", problem)

        max_velocity_dps = self.number(t, "max_velocity_dps", f, positive=True, within=VELOCITY_RANGE_DPS)
        max_acceleration_dps2 = self.number(t, "max_acceleration_dps2", f, positive=True,
                                            within=ACCELERATION_RANGE_DPS2)

        hold_deg: float | None = None
        if "hold_deg" in t:
            if walking:
                raise self.fail(f"{f}.hold_deg", "only non-walking joints (roll and yaw) may be held: the walk "
                                                 "moves every hip, knee and ankle pitch joint")
            hold_deg = self.number(t, "hold_deg", f, within=ANGLE_RANGE_DEG)
            if not min_deg <= hold_deg <= max_deg:
                raise self.fail(f"{f}.hold_deg", f"{hold_deg} is outside the joint's limits {min_deg}..{max_deg} deg")

        return JointConfig(name=name, id=servo_id, model=model, zero_tick=zero_tick, direction=direction,
                           min_deg=min_deg, max_deg=max_deg, max_velocity_dps=max_velocity_dps,
                           max_acceleration_dps2=max_acceleration_dps2, hold_deg=hold_deg)

    def bus_wide_checks(self, joints: tuple[JointConfig, ...], bus: BusSettings) -> None:
        seen: dict[int, str] = {}
        for j in joints:
            if j.id in seen:
                raise self.fail(f"joints.{j.name}.id", f"id {j.id} is already used by joints.{seen[j.id]} "
                                                      f"(ids must be unique on one bus)")
            seen[j.id] = j.name
        first = joints[0]
        for j in joints[1:]:
            if j.model.byte_order != first.model.byte_order:
                raise self.fail(f"joints.{j.name}.model",
                                f"{j.model.name} sends {j.model.byte_order}-endian positions but "
                                f"joints.{first.name} ({first.model.name}) is {first.model.byte_order}-endian; "
                                f"one bus needs one byte order (e.g. Feetech STS or SCS, not both)")


def angle_outside_servo(model: ServoModel, zero_tick: int, direction: int, angle_deg: float) -> str | None:
    """Why ``angle_deg`` cannot be reached with this zero tick and direction (its tick lies outside the
    servo's range, and the allowed angles are given), or None when it can."""
    tick = int(angle_rad_to_ticks(math.radians(angle_deg), zero_tick, direction, model.ticks_per_rad))
    if model.min_tick <= tick <= model.max_tick:
        return None
    lo, hi = sorted(_tick_range_deg(model, zero_tick, direction))
    return (f"{angle_deg} deg maps to tick {tick}, outside the {model.name}'s range {model.min_tick}..{model.max_tick} "
            f"(with zero_tick {zero_tick} and direction {direction} the allowed angles are {lo:.1f}..{hi:.1f} deg)")


def _tick_range_deg(model: ServoModel, zero_tick: int, direction: int) -> tuple[float, float]:
    """The angles (deg) at the two ends of the servo's tick range, for this zero_tick and direction."""
    return tuple(math.degrees((tick - zero_tick) / (direction * model.ticks_per_rad))
                 for tick in (model.min_tick, model.max_tick))  # type: ignore[return-value]
