"""The data classes of a robot config (gaitbot.robot.config reads them from TOML, field by field).

Their field names are the config's keys: gaitbot.robot.config derives each table's allowed keys from them,
so a key and its field are written once."""

from __future__ import annotations

from dataclasses import dataclass, fields
from functools import cached_property
from pathlib import Path

from gaitbot.gait.balance.settings import BalanceSettings
from gaitbot.gait.body import LEG_LINKS, BodyGeometry, BodyModel, LinkInertial
from gaitbot.gait.steer.limits import SteerLimits
from gaitbot.robot.calibration import Calibration
from gaitbot.robot.health import HealthSettings
from gaitbot.robot.imu_settings import ImuSettings
from gaitbot.servos.models import ServoModel

TORSO_HEIGHT_LEGS = 0.6
"""A planar robot's torso (``[mass] torso_kg``) is a box this many leg lengths tall standing on the hips."""


def field_names(cls, *, without: tuple[str, ...] = ()) -> tuple[str, ...]:
    """A data class's field names (a TOML table's allowed keys), in order, less ``without``."""
    return tuple(f.name for f in fields(cls) if f.name not in without)


@dataclass(frozen=True)
class Geometry:
    """Leg dimensions in metres: hip-knee, knee-ankle, foot length (heel to toe), distance between
    the hip joints, ankle axis above the sole, and heel behind the ankle axis (0: the heel is the
    ankle projected on the sole, Jing et al.'s foot). For 3D (gaitbot.gait.body): the sole's width
    (None: not given; 3D robots must), its centre outward of the ankle, and the hip point below the
    root (the pelvis frame's origin)."""

    thigh_m: float
    shank_m: float
    foot_m: float
    hip_width_m: float
    ankle_height_m: float = 0.0
    heel_back_m: float = 0.0
    foot_width_m: float | None = None
    sole_outward_m: float = 0.0
    hip_below_root_m: float = 0.0

    def body_geometry(self) -> BodyGeometry:
        """The 3D leg geometry; a sole of unknown width is taken as a quarter of its length either side."""
        width = self.foot_width_m if self.foot_width_m is not None else self.foot_m / 2
        return BodyGeometry(self.thigh_m, self.shank_m, self.foot_m, width, self.hip_width_m, self.ankle_height_m,
                            self.heel_back_m, self.sole_outward_m, self.hip_below_root_m)


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
    """A whole robot: joints are the moving joints in canonical order (gaitbot.gait.joints), then the
    held ones (``hold_deg``) in canonical order; the bus addresses them in this order."""

    path: Path
    name: str
    geometry: Geometry
    gait: GaitSettings
    bus: BusSettings
    joints: tuple[JointConfig, ...]
    mass: MassSettings = MassSettings()
    servo: ServoSettings = ServoSettings()
    terrain: TerrainReach | None = None
    calibration_file: Path | None = None  # the calibration file applied on top (gaitbot.robot.calibration_file)
    health: HealthSettings = HealthSettings()  # [health] overrides (gaitbot.robot.health)
    balance: BalanceSettings = BalanceSettings()
    links: tuple[tuple[str, LinkInertial], ...] | None = None
    boom: bool = False
    draft: str | None = None  # [robot] draft: a config imported with placeholders (hardware refuses it)
    steer: SteerLimits | None = None  # [steer]: steering limits (gaitbot.robot.steer_settings); None: straight only
    imu: ImuSettings = ImuSettings()  # [imu], [feedback], [fall] (gaitbot.robot.imu_settings)

    @cached_property
    def body(self) -> BodyModel:
        """Every link's mass: the ``[links.*]`` table, else the four ``[mass]`` segments (planar robots)."""
        geometry = self.geometry.body_geometry()
        if self.links is not None:
            links = dict(self.links)
            return BodyModel(geometry, links["torso"], {name: links[name] for name in LEG_LINKS})
        m = self.mass
        return BodyModel.from_segment_masses(geometry, m.torso_kg, m.thigh_kg, m.shank_kg, m.foot_kg,
                                             TORSO_HEIGHT_LEGS * geometry.leg_length_m)

    @property
    def walking_joints(self) -> tuple[JointConfig, ...]:
        """The joints the gait moves (no ``hold_deg``), in canonical order."""
        return tuple(j for j in self.joints if j.hold_deg is None)

    @property
    def held_joints(self) -> tuple[JointConfig, ...]:
        return tuple(j for j in self.joints if j.hold_deg is not None)

    @property
    def walking_joint_names(self) -> tuple[str, ...]:
        return tuple(j.name for j in self.walking_joints)

    @property
    def is_3d(self) -> bool:
        """True when the legs move in roll as well as pitch (hip and ankle roll joints that walk):
        such a robot can shift its weight sideways over one foot; a pitch-only one needs a boom."""
        return "hip_roll_left" in self.walking_joint_names and "ankle_roll_left" in self.walking_joint_names

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
        return Calibration.of(self.joints)

    @property
    def models_by_id(self) -> dict[int, ServoModel]:
        """Servo model per id, in joint order (what the bus backends take as ``models``)."""
        return {j.id: j.model for j in self.joints}

    def joint(self, name: str) -> JointConfig:
        for j in self.joints:
            if j.name == name:
                return j
        raise KeyError(f"{self.path}: no joint {name!r} (joints: {', '.join(self.joint_names)})")
