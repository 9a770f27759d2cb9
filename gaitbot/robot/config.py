"""Robot description from a TOML file: geometry, gait settings, bus and joints, validated.

Why so strict: a config error found on the bench means a servo driven into its end stop or a
mirror-mounted knee bending backwards. Every value is checked when the file is loaded (through
gaitbot.fields, the one field-checked reader) and the first problem is reported as ONE line naming
the file, the field and what is allowed::

    config/xl430-biped.toml: joints.knee_pitch_left.min_deg: 120.0 is above max_deg 110.0

The file format is written down in docs/robot-config.md.

Checks that need another room (whether the bus can carry ``gait.rate_hz`` frames at
``bus.baudrate``: ``gaitbot.bus.budget``) are passed in by the caller through ``extra_checks``,
because this module imports only from rooms to its left (gait -> robot -> bus -> stream).
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from functools import cached_property
from importlib import resources
from pathlib import Path
from typing import Any

from gaitbot.fields import FieldError, Fields, kind, read_toml
from gaitbot.gait.geometry import LegGeometry
from gaitbot.gait.trajectory import WALKING_JOINTS
from gaitbot.gait.walker import WalkSettings, make_context
from gaitbot.robot.calibration import Calibration, angle_rad_to_ticks
from gaitbot.robot.gains import GainError, gain_for_error
from gaitbot.servos import BACKENDS, dynamixel, feetech, max_servo_id, vendor
from gaitbot.servos.models import SERVO_MODELS, ServoModel

DEFAULT_ROBOT = "xl430-biped"


class ConfigError(FieldError):
    """A robot config is unusable. The message is one line: ``<file>: <field>: <what is wrong>``.

    Other modules that check a loaded config (the bus budget) build theirs with ``ConfigError(path,
    field, reason)`` so every config complaint looks the same.
    """


# ---------------------------------------------------------------------------------------------
# The data classes


@dataclass(frozen=True)
class Geometry:
    """Leg dimensions in metres: hip-knee, knee-ankle, foot length (heel to toe), distance between
    the hip joints, ankle axis above the sole, and heel behind the ankle axis (0: the heel is the
    ankle projected on the sole, seed 000's foot)."""

    thigh_m: float
    shank_m: float
    foot_m: float
    hip_width_m: float
    ankle_height_m: float = 0.0
    heel_back_m: float = 0.0


@dataclass(frozen=True)
class GaitSettings:
    """Walking parameters: cycle period (s), longest step (m), swing-foot clearance (m), frame rate (Hz)."""

    cycle_s: float
    max_step_m: float
    clearance_m: float
    rate_hz: float


@dataclass(frozen=True)
class TerrainReach:
    """The optional ``[terrain]`` table: what one step can do between surfaces (metres), as measured by
    tools/terrain_envelope.py: highest rise, deepest drop, widest gap stepped over on the level."""

    max_rise_m: float
    max_drop_m: float
    max_gap_m: float


@dataclass(frozen=True)
class BusSettings:
    """The serial bus. ``protocol`` is the Dynamixel protocol version; Feetech buses always get 1.0,
    the one (Dynamixel-1.0-shaped) protocol Feetech servos speak (gaitbot.servos.feetech.PROTOCOLS)."""

    backend: str
    protocol: float
    port: str
    baudrate: int
    torque_off_on_exit: bool = False


@dataclass(frozen=True)
class JointConfig:
    """One servo joint.

    Angles are flexion positive. ``zero_tick`` is the tick at angle 0; ``direction`` is +1 or -1
    (-1 for mirror-mounted servos). ``hold_deg`` is set only for non-walking joints, which are
    held at that angle while walking.
    """

    name: str
    id: int
    model: ServoModel
    zero_tick: int
    direction: int
    min_deg: float
    max_deg: float
    max_velocity_dps: float
    max_acceleration_dps2: float
    hold_deg: float | None = None


@dataclass(frozen=True)
class MassSettings:
    """Link masses in kg for the simulated robot (``[mass]``, optional): the torso (with the hip
    servos, battery and controller) and, per leg, thigh (with the knee servo), shank (with the ankle
    servo) and foot. The defaults make a 1.5 kg robot: 0.80 + 2 x (0.14 + 0.14 + 0.07)."""

    torso_kg: float = 0.80
    thigh_kg: float = 0.14
    shank_kg: float = 0.14
    foot_kg: float = 0.07

    @property
    def total_kg(self) -> float:
        return self.torso_kg + 2.0 * (self.thigh_kg + self.shank_kg + self.foot_kg)


@dataclass(frozen=True)
class ServoSettings:
    """The servos' drive (``[servo]``, optional).

    ``full_torque_error_deg`` is a real setting: the position error (degrees) at which every servo's
    position loop gives full output, smaller is stiffer. A session writes it to each servo's gain
    register before torque goes on (gaitbot.robot.gains); None leaves the factory gains alone.
    ``stall_torque_nm`` (N m) and ``no_load_speed_rpm`` (rev/min) override the servo models' datasheet
    figures (gaitbot.servos.models) for the simulated robot only; None keeps them."""

    stall_torque_nm: float | None = None
    no_load_speed_rpm: float | None = None
    full_torque_error_deg: float | None = None


@dataclass(frozen=True)
class RobotConfig:
    """A whole robot: joints are the walking joints in WALKING_JOINTS order, then the held joints."""

    path: Path
    name: str
    geometry: Geometry
    gait: GaitSettings
    bus: BusSettings
    joints: tuple[JointConfig, ...]
    mass: MassSettings = MassSettings()
    servo: ServoSettings = ServoSettings()
    terrain: TerrainReach | None = None

    @property
    def walking_joints(self) -> tuple[JointConfig, ...]:
        return self.joints[: len(WALKING_JOINTS)]

    @property
    def held_joints(self) -> tuple[JointConfig, ...]:
        return self.joints[len(WALKING_JOINTS):]

    @property
    def joint_names(self) -> tuple[str, ...]:
        return tuple(j.name for j in self.joints)

    @property
    def ids(self) -> tuple[int, ...]:
        """Servo ids in joint order."""
        return tuple(j.id for j in self.joints)

    @cached_property
    def calibration(self) -> Calibration:
        """Angles <-> ticks for every joint, built once per config."""
        return Calibration.of(self.joints, len(WALKING_JOINTS))

    @property
    def models_by_id(self) -> dict[int, ServoModel]:
        """Servo model per id, in joint order (what the bus backends take as ``models``)."""
        return {j.id: j.model for j in self.joints}

    def joint(self, name: str) -> JointConfig:
        for j in self.joints:
            if j.name == name:
                return j
        raise KeyError(f"{self.path}: no joint {name!r} (joints: {', '.join(self.joint_names)})")


# A check run on a loaded config; raises ConfigError. See load_robot_config(extra_checks=...).
ConfigCheck = Callable[[RobotConfig], None]


# ---------------------------------------------------------------------------------------------
# Finding the shipped configs


def shipped_config_dirs() -> list[Path]:
    """Directories holding the shipped robot files: the wheel's ``gaitbot/_config`` first (pyproject
    force-includes the top-level ``config/`` there), then ``<repo>/config`` for source checkouts."""
    dirs: list[Path] = []
    try:
        packaged = resources.files("gaitbot") / "_config"
        if isinstance(packaged, Path) and packaged.is_dir():
            dirs.append(packaged)
    except (ModuleNotFoundError, OSError):  # pragma: no cover - gaitbot is importable if we run
        pass
    checkout = Path(__file__).resolve().parents[2]
    # Only a source checkout (pyproject.toml beside gaitbot/): in an installed wheel parents[2] is
    # site-packages, where a "config" directory would belong to some other distribution.
    if (checkout / "pyproject.toml").is_file() and (checkout / "config").is_dir():
        dirs.append(checkout / "config")
    return dirs


def shipped_config_names() -> list[str]:
    """Names of the shipped robots (file stems), sorted."""
    return sorted({p.stem for d in shipped_config_dirs() for p in d.glob("*.toml")})


def resolve_config(name_or_path: str | Path) -> Path:
    """A config file from a path, or from the bare name of a shipped robot (``xl430-biped``).

    An existing file wins; otherwise a bare name (no directory part) is looked up among the shipped
    configs. Raises ConfigError listing the shipped names when neither exists.
    """
    path = Path(name_or_path)
    if path.is_file():
        return path
    text = str(name_or_path)
    if len(path.parts) == 1:
        stem = text[:-5] if text.endswith(".toml") else text
        for directory in shipped_config_dirs():
            candidate = directory / f"{stem}.toml"
            if candidate.is_file():
                return candidate
    shipped = ", ".join(shipped_config_names()) or "none found"
    raise ConfigError(text, "file", f"no such file, and not the name of a shipped robot (shipped: {shipped})")


def default_config_path() -> Path:
    """The built-in default robot's file (xl430-biped)."""
    return resolve_config(DEFAULT_ROBOT)


# ---------------------------------------------------------------------------------------------
# Loading


def load_robot_config(path: str | Path, *, extra_checks: Iterable[ConfigCheck] = ()) -> RobotConfig:
    """Read and validate a robot config; raise ConfigError (one line) on the first problem.

    ``extra_checks`` are run on the validated config, in order; this is the hook for checks that
    live in rooms to the right of this one, e.g. the integrator passes
    ``gaitbot.bus.budget``'s check that the bus can carry ``gait.rate_hz`` frames per second.
    """
    path = Path(path)
    data = read_toml(path, ConfigError)
    config = _Reader(path).robot(data)
    for check in extra_checks:
        check(config)
    return config


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

_TOP_KEYS = ("robot", "geometry", "gait", "bus", "joints", "mass", "servo", "terrain")
_MASS_KEYS = ("torso_kg", "thigh_kg", "shank_kg", "foot_kg")
_SERVO_KEYS = ("stall_torque_nm", "no_load_speed_rpm", "full_torque_error_deg")
_TERRAIN_KEYS = ("max_rise_m", "max_drop_m", "max_gap_m")
_ROBOT_KEYS = ("name",)
_GEOMETRY_KEYS = ("thigh_m", "shank_m", "foot_m", "hip_width_m", "ankle_height_m", "heel_back_m")
_GAIT_KEYS = ("cycle_s", "max_step_m", "clearance_m", "rate_hz")
_BUS_KEYS = ("backend", "protocol", "port", "baudrate", "torque_off_on_exit")
_JOINT_KEYS = ("id", "model", "zero_tick", "direction", "min_deg", "max_deg", "max_velocity_dps",
               "max_acceleration_dps2", "hold_deg")


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
        mass = self.mass(self.optional_table(data, "mass", "mass", _MASS_KEYS))
        servo = self.servo(self.optional_table(data, "servo", "servo", _SERVO_KEYS))
        self.gains_settable(joints, servo)
        self.walkable(geometry, gait)
        terrain = None
        if "terrain" in data:
            t = self.table(data, "terrain", "terrain", _TERRAIN_KEYS)
            terrain = TerrainReach(*(self.number(t, key, "terrain", non_negative=True, within=LIMB_RANGE_M)
                                     for key in _TERRAIN_KEYS))
        return RobotConfig(path=self.path, name=name, geometry=geometry, gait=gait, bus=bus, joints=joints,
                           mass=mass, servo=servo, terrain=terrain)

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

    def mass(self, t: dict) -> MassSettings:
        defaults = MassSettings()
        return MassSettings(**{k: self.number(t, k, "mass", positive=True, default=getattr(defaults, k),
                                              within=MASS_RANGE_KG)
                               for k in _MASS_KEYS})

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
        )
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
        protocol = feetech.PROTOCOLS[0]
        if backend == "dynamixel":
            allowed = " or ".join(str(p) for p in dynamixel.PROTOCOLS)
            protocol = self.number(t, "protocol", f)
            if protocol not in dynamixel.PROTOCOLS:
                raise self.fail("bus.protocol", f"unknown Dynamixel protocol {protocol} (allowed: {allowed})")
        # Feetech servos speak one protocol; a protocol key there is accepted and ignored (always 1.0).
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
        if "joints" not in data:
            raise self.fail("joints", f"missing section (expected [joints.<name>] for {', '.join(WALKING_JOINTS)})")
        tables = data["joints"]
        if not isinstance(tables, dict):
            raise self.fail("joints", f"must be tables [joints.<name>], got {kind(tables)}")
        for name in WALKING_JOINTS:
            if name not in tables:
                others = [n for n in tables if n not in WALKING_JOINTS]
                close = difflib.get_close_matches(name, others, n=1)
                hint = f"; is {close[0]!r} a typo of it?" if close else ""
                raise self.fail(f"joints.{name}", f"missing walking joint (all of {', '.join(WALKING_JOINTS)} "
                                                  f"are required{hint})")
        order = list(WALKING_JOINTS) + [n for n in tables if n not in WALKING_JOINTS]
        joints = tuple(self.joint(name, tables[name], bus) for name in order)
        self.bus_wide_checks(joints, bus)
        return joints

    def joint(self, name: str, t: Any, bus: BusSettings) -> JointConfig:
        f = f"joints.{name}"
        if not isinstance(t, dict):
            raise self.fail(f, f"must be a table [{f}], got {kind(t)}")
        self.no_unknown_keys(t, f, _JOINT_KEYS)
        walking = name in WALKING_JOINTS

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
            tick = int(angle_rad_to_ticks(math.radians(angle_deg), zero_tick, direction, model.ticks_per_rad))
            if not model.min_tick <= tick <= model.max_tick:
                lo, hi = sorted(_tick_range_deg(model, zero_tick, direction))
                raise self.fail(f"{f}.{key}", f"{angle_deg} deg maps to tick {tick}, outside the {model_name}'s "
                                              f"range {model.min_tick}..{model.max_tick} (with zero_tick {zero_tick} "
                                              f"and direction {direction} the allowed angles are "
                                              f"{lo:.1f}..{hi:.1f} deg)")

        max_velocity_dps = self.number(t, "max_velocity_dps", f, positive=True, within=VELOCITY_RANGE_DPS)
        max_acceleration_dps2 = self.number(t, "max_acceleration_dps2", f, positive=True,
                                            within=ACCELERATION_RANGE_DPS2)

        hold_deg: float | None = None
        if walking:
            if "hold_deg" in t:
                raise self.fail(f"{f}.hold_deg", "only non-walking joints are held at a fixed angle; "
                                                 "remove it from a walking joint")
        else:
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


def _tick_range_deg(model: ServoModel, zero_tick: int, direction: int) -> tuple[float, float]:
    """The angles (deg) at the two ends of the servo's tick range, for this zero_tick and direction."""
    return tuple(math.degrees((tick - zero_tick) / (direction * model.ticks_per_rad))
                 for tick in (model.min_tick, model.max_tick))  # type: ignore[return-value]
