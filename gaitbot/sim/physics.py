"""The simulated robot's state, advanced on the streamer's clock.

Time is the clock's: ``advance_to(t_s)`` steps the physics up to ``t_s`` in whole timesteps, so a
run on a VirtualClock is deterministic and runs as fast as the CPU allows. A frame (1 / rate_hz)
is ``substeps`` timesteps; at the end of every frame (the instant the next goal may arrive) the
observers are called, e.g. the measurements of metrics.py and the video of video.py. Between two
frame ends only cheap array work is done per timestep: each servo's peak effort and the time
each sole touches the floor, for the observers to read and reset.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from gaitbot.sim import import_mujoco
from gaitbot.sim.model import SIDES, build_mjcf, joint_drives, substeps_per_frame
from gaitbot.sim.model3d import SUPPORTS, build_mjcf_3d
from gaitbot.robot.config import RobotConfig


class SimRobot:
    """The MuJoCo model of ``config``, standing straight at t = 0 with its servos limp.

    ``support``: "free" (a free-floating torso: the 3D model of gaitbot.sim.model3d), "boom" or
    "boom-pitch" (the torso on a boom, its pitch held or free; None: "boom-pitch" if ``free_pitch`` else
    "boom"). A pitch-only robot on the boom is today's planar model (gaitbot.sim.model), so its figures
    stay what they were; every other case is the 3D model with every joint of the config.
    The modelled joints (``joint_names``: the walking joints, then in the 3D model the held ones) are
    indexed in that order everywhere here.
    ``effort_peak``: per servo, the largest |commanded torque| / stall torque since the observers
    last reset it (1.0 = saturated); ``touch_steps``: per sole (left, right), timesteps in contact;
    ``full_torque_error_deg``: per servo, its stiffness now (factory until a gain is written).
    """

    def __init__(self, config: RobotConfig, rate_hz: float, free_pitch: bool = False, support: str | None = None) -> None:
        self.mujoco = mujoco = import_mujoco()
        self.config = config
        support = support or ("boom-pitch" if free_pitch else "boom")
        if support not in SUPPORTS:
            raise ValueError(f"support must be one of {SUPPORTS}, got {support!r}")
        self.support = support
        self.free_pitch = support == "boom-pitch"
        self.planar = support != "free" and not config.is_3d
        if self.planar:
            self.drives = joint_drives(config)
            xml = build_mjcf(config, rate_hz, self.free_pitch)
        else:
            self.drives = joint_drives(config, config.joints)
            xml = build_mjcf_3d(config, self.drives, rate_hz, support)
        self.model = mujoco.MjModel.from_xml_string(xml)
        self.data = mujoco.MjData(self.model)
        self.joint_names = tuple(d.name for d in self.drives)
        self.substeps = substeps_per_frame(rate_hz)
        self.frame_s = 1.0 / rate_hz
        self.timestep_s = float(self.model.opt.timestep)
        model = self.model
        self.qpos_index = np.array([model.joint(d.name).qposadr[0] for d in self.drives])
        self.actuator_index = np.array([model.actuator(d.name).id for d in self.drives])
        self.stall_nm = np.array([d.stall_torque_nm for d in self.drives])
        self.full_torque_error_deg = np.array([d.full_torque_error_deg for d in self.drives])
        self._kp = model.actuator_gainprm[self.actuator_index, 0].copy()
        self.torque_on = np.zeros(len(self.drives), dtype=bool)
        self.floor_geom = model.geom("floor").id
        self.sole_geoms = np.array([model.geom(f"sole_{side}").id for side in SIDES])
        self.sole_side_of = {int(g): side for side, g in enumerate(self.sole_geoms)}  # geom -> index in SIDES
        self.foot_bodies = np.array([model.body(f"foot_{side}").id for side in SIDES])
        self.ankle_in_foot_m = np.zeros((len(SIDES), 3))  # the ankle point in each foot body (its origin here)
        self.foot_axes = np.array([np.eye(3)] * len(SIDES))  # gaitbot's foot axes in each foot body
        self.torso_body = model.body("torso").id
        self.imu_body = self.torso_body  # the body the simulated IMU reads (gaitbot.sim.imu)
        self._touch_adr = np.array([model.sensor(f"touch_{side}").adr[0] for side in SIDES])
        if list(self.actuator_index) != list(range(model.nu)) or list(self._touch_adr) != list(range(model.nsensordata)):
            raise RuntimeError("the model's actuators and sensors must be in joint and side order")  # build_mjcf's
        self.steps = 0
        self.effort_peak = np.zeros(len(self.drives))
        self.touch_steps = np.zeros(len(SIDES), dtype=np.int64)
        self._force_hi = np.zeros(model.nu)
        self._force_lo = np.zeros(model.nu)
        self._touching = np.zeros(len(SIDES), dtype=bool)
        self.observers: list[Callable[[SimRobot], None]] = []
        for i in range(len(self.drives)):
            self.set_torque(i, False)
        mujoco.mj_forward(self.model, self.data)

    # --- what the servos are told ------------------------------------------------------------
    def set_goal(self, joint: int, angle_rad: float) -> None:
        self.data.ctrl[self.actuator_index[joint]] = angle_rad

    def goals_rad(self) -> np.ndarray:
        return self.data.ctrl[self.actuator_index].copy()

    def set_full_torque_error(self, joint: int, error_deg: float) -> None:
        """The servo's stiffness, as its gain register sets it: full torque at ``error_deg`` degrees of
        position error (kp = stall / error; an infinite error, a gain of 0, pushes nothing)."""
        self.full_torque_error_deg[joint] = error_deg
        self._kp[joint] = self.stall_nm[joint] / math.radians(error_deg)
        self.set_torque(joint, bool(self.torque_on[joint]))

    def set_torque(self, joint: int, enabled: bool) -> None:
        """A servo with torque off pushes nothing (its gearmotor's back-EMF damping stays)."""
        a = self.actuator_index[joint]
        kp = self._kp[joint] if enabled else 0.0
        self.model.actuator_gainprm[a, 0] = kp
        self.model.actuator_biasprm[a, 1] = -kp
        self.torque_on[joint] = enabled

    # --- what the robot does -----------------------------------------------------------------
    @property
    def time_s(self) -> float:
        """Simulated seconds since the start, exact at frame ends (whole frames, then substeps)."""
        frames, substeps = divmod(self.steps, self.substeps)
        return frames * self.frame_s + substeps * self.timestep_s

    def joint_angles_rad(self) -> np.ndarray:
        return self.data.qpos[self.qpos_index].copy()

    def torso_position_m(self) -> np.ndarray:
        """(x, z) of the hip point (the torso body's origin) in the world."""
        return self.data.xpos[self.torso_body][[0, 2]].copy()

    def torso_xyz_m(self) -> np.ndarray:
        """The root (the torso body's origin) in the world."""
        return self.data.xpos[self.torso_body].copy()

    def torso_rpy_rad(self) -> np.ndarray:
        """The torso's roll, pitch (forward lean positive) and yaw (Z-Y-X angles of its rotation)."""
        if self.planar:
            return np.array([0.0, self.torso_pitch_rad(), 0.0])
        r = self.data.xmat[self.torso_body].reshape(3, 3)
        return np.array([math.atan2(r[2, 1], r[2, 2]), math.asin(-max(-1.0, min(1.0, r[2, 0]))),
                         math.atan2(r[1, 0], r[0, 0])])

    def torso_pitch_rad(self) -> float:
        """Forward lean of the torso (0 when held)."""
        if self.support == "free":
            return float(self.torso_rpy_rad()[1])
        if not self.free_pitch:
            return 0.0
        return float(self.data.qpos[self.model.joint("boom_pitch").qposadr[0]])

    def place(self, angles_rad: dict[str, float], root_m) -> None:
        """Put the robot in a pose before anything moves: joint angles by name, the root at ``root_m``
        (x, y, z; on the boom only x and z count). Velocities zero; the servos' goals follow."""
        data, model = self.data, self.model
        for i, name in enumerate(self.joint_names):
            if name in angles_rad:
                data.qpos[self.qpos_index[i]] = angles_rad[name]
                data.ctrl[self.actuator_index[i]] = angles_rad[name]
        root = np.asarray(root_m, dtype=float)
        if self.support == "free":
            data.qpos[:3] = root
            data.qpos[3:7] = (1.0, 0.0, 0.0, 0.0)
        else:
            standing = model.body_pos[self.torso_body]
            data.qpos[model.joint("boom_x").qposadr[0]] = root[0] - standing[0]
            data.qpos[model.joint("boom_z").qposadr[0]] = root[2] - standing[2]
        data.qvel[:] = 0.0
        self.mujoco.mj_forward(model, data)

    def push(self, force_y_n: float, force_x_n: float = 0.0) -> None:
        """A horizontal force on the torso's centre of mass (N; y positive to the left, x forward in the
        world) until changed."""
        self.data.xfrc_applied[self.torso_body, 0] = force_x_n
        self.data.xfrc_applied[self.torso_body, 1] = force_y_n

    def advance_to(self, t_s: float) -> None:
        """Step the physics to the whole timestep nearest ``t_s``; call the observers at each frame end."""
        remaining = int(round((t_s - self.time_s) / self.timestep_s))
        while remaining > 0:
            chunk = min(remaining, self.substeps - self.steps % self.substeps)
            self._step(chunk)
            remaining -= chunk
            if self.steps % self.substeps == 0:
                for observer in self.observers:
                    observer(self)

    def _step(self, count: int) -> None:
        """``count`` physics steps, keeping each servo's force extremes and each sole's contact time.

        In-place ufuncs on whole arrays (actuators and touch sensors are built in joint and side
        order): this loop is most of the simulation's cost."""
        step, model, data = self.mujoco.mj_step, self.model, self.data
        force, touch = data.actuator_force, data.sensordata
        hi, lo, touching, steps_touching = self._force_hi, self._force_lo, self._touching, self.touch_steps
        hi[:] = 0.0
        lo[:] = 0.0
        maximum, minimum, greater, add = np.maximum, np.minimum, np.greater, np.add
        for _ in range(count):
            step(model, data)
            maximum(hi, force, out=hi)
            minimum(lo, force, out=lo)
            greater(touch, 0.0, out=touching)
            add(steps_touching, touching, out=steps_touching)
        np.maximum(self.effort_peak, np.maximum(hi, -lo) / self.stall_nm, out=self.effort_peak)
        self.steps += count

    def self_contacts(self) -> set[tuple[int, int]]:
        """The pairs of the robot's own bodies (body ids, lower first) in contact now: a knee on a knee, a sole on
        the other ankle. gaitbot's own models collide the soles with the floor only; another author's may not.
        The robot's bodies are those of the torso's tree (a scene's props and floor are not)."""
        data, body, root = self.data, self.model.geom_bodyid, self.model.body_rootid
        robot = root[self.torso_body]
        out = set()
        for i in range(data.ncon):
            contact = data.contact[i]
            b1, b2 = int(body[contact.geom1]), int(body[contact.geom2])
            if root[b1] == robot and root[b2] == robot and contact.dist <= 0.0:
                out.add((min(b1, b2), max(b1, b2)))
        return out

    def floor_contacts(self) -> list[tuple[int, np.ndarray]]:
        """Every contact with the floor now: (geom id of the robot's geom, contact point (3,) world)."""
        data, floor = self.data, self.floor_geom
        out = []
        for i in range(data.ncon):
            contact = data.contact[i]
            g1, g2 = int(contact.geom1), int(contact.geom2)
            if floor in (g1, g2) and contact.dist <= 0.0:
                out.append((g2 if g1 == floor else g1, contact.pos.copy()))
        return out
