"""Another author's MuJoCo model of the robot behind the simulated bus (``walk --sim --sim-model --sim-map``).

The model is used as it is: its floor, contacts, inertias, joint damping and its own position actuators,
whose gains and force limits are what is being tested (a gain the session writes to a servo is recorded
in the packets but changes nothing here). The mapping file (gaitbot.sim.sim_map) says which model joint
is which gaitbot joint and at what the model's other actuated joints are held. Refused in one line (exit
2): a model MuJoCo cannot load, one without a free-floating body, a mapped or held name the model does not
have, an actuated joint left neither mapped nor held, a mapped joint without a position actuator, a robot
config joint left unmapped, and a sign or axis the model's forward kinematics contradicts
(gaitbot.sim.foreign_check, at a few poses against gaitbot's own kinematics).

Two things are adapted, and said: the timestep is shortened to a whole number of steps per 60 Hz frame
(the model's 2 ms becomes 1.67 ms: the session's clock advances the physics by whole frames), and a model
without a floor (no plane in its worldbody, e.g. Menagerie's op3.xml without its scene.xml) gets a plane at
z = 0. The robot stands in the walk's first pose with its lowest sole point on the floor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gaitbot.errors import UserError
from gaitbot.gait.joints import LEG_JOINT_KINDS, SIDES
from gaitbot.robot.config import RobotConfig
from gaitbot.sim import import_mujoco
from gaitbot.sim.physics import SimRobot
from gaitbot.sim.sim_map import SimMap, SimMapError, hold_rad


class ForeignModelError(UserError):
    """A --sim-model file that cannot be walked (one line naming the file and what is wrong; exit 2)."""


@dataclass(frozen=True)
class Mapped:
    """A gaitbot joint on the model: its joint id, qpos address, sign, actuator id."""

    name: str
    model_joint: str
    joint_id: int
    qpos: int
    sign: int
    actuator: int


def substeps_per_frame(frame_s: float, timestep_s: float) -> int:
    """Whole physics steps in a frame: the model's timestep, shortened if need be to divide the frame. A
    timestep written to a few significant digits (0.000980392 for 1/1020 s) is taken as the divisor it
    rounds (17 steps of a 60 Hz frame, not 18): within 1e-4 of a whole count."""
    count = frame_s / timestep_s
    return max(1, round(count)) if abs(count - round(count)) < 1e-4 * count else math.ceil(count)


def load_model(mujoco, path: Path):
    """The compiled model of ``path`` (a plane floor added if it has none) and notes on what was adapted."""
    label = f"--sim-model {path}"
    if not path.is_file():
        raise ForeignModelError(f"{label}: no such file")
    try:
        spec = mujoco.MjSpec.from_file(str(path))
        model = spec.compile()
    except Exception as exc:  # noqa: BLE001 - MuJoCo's own message, first line
        first = (str(exc).strip().splitlines() or ["unknown error"])[0]
        raise ForeignModelError(f"{label}: MuJoCo cannot load it ({first})") from None
    notes = []
    if _floor_geom(mujoco, model) is None:
        spec.worldbody.add_geom(name="gaitbot_floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 0.05])
        model = spec.compile()
        notes.append("the model has no floor (no plane in its worldbody): a plane was added at z = 0")
    return model, notes


def _floor_geom(mujoco, model) -> int | None:
    for g in range(model.ngeom):
        if model.geom_bodyid[g] == 0 and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE:
            return g
    return None


def resolve_joints(mujoco, model, config: RobotConfig, sim_map: SimMap) -> tuple[list[Mapped], dict[int, float]]:
    """The mapped joints (the config's order) and the held ones (actuator id -> angle rad), or SimMapError."""
    fail = lambda field, reason: SimMapError(sim_map.path, field, reason)  # noqa: E731
    config_names = [j.name for j in config.joints]
    for name in config.walking_joint_names:
        if name not in sim_map.joints:
            raise fail("joints", f"{name} is not mapped: every joint robot {config.name} moves needs its model joint")
    actuator_of: dict[int, int] = {}
    for a in range(model.nu):
        if model.actuator_trntype[a] != mujoco.mjtTrn.mjTRN_JOINT:
            raise fail("joints", f"the model's actuator {model.actuator(a).name!r} does not drive a joint "
                                 "(tendon or site transmissions are not supported)")
        actuator_of.setdefault(int(model.actuator_trnid[a, 0]), a)
    mapped = []
    for name in sorted(sim_map.joints, key=lambda n: config_names.index(n) if n in config_names else -1):
        link = sim_map.joints[name]
        if name not in config_names:
            raise fail(f"joints.{name}", f"not a joint of robot {config.name} (its joints: {', '.join(config_names)})")
        jid = _joint_id(mujoco, model, link.model_joint)
        if jid is None or model.jnt_type[jid] != mujoco.mjtJoint.mjJNT_HINGE:
            raise fail(f"joints.{name}", f"the model has no hinge joint {link.model_joint!r}"
                                         f"{_did_you_mean(model, link.model_joint)}")
        a = actuator_of.get(jid)
        if a is None or not _is_position_servo(mujoco, model, a):
            raise fail(f"joints.{name}", f"the model's joint {link.model_joint!r} has no position actuator "
                                         "(the model's own servos drive the mapped joints)")
        mapped.append(Mapped(name, link.model_joint, jid, int(model.jnt_qposadr[jid]), link.sign, a))
    held = {}
    for joint_name, angle in hold_rad(sim_map).items():
        jid = _joint_id(mujoco, model, joint_name)
        if jid is None:
            raise fail(f"hold_deg.{joint_name}", f"the model has no joint {joint_name!r}{_did_you_mean(model, joint_name)}")
        if jid not in actuator_of:
            raise fail(f"hold_deg.{joint_name}", "the model's joint has no actuator to hold it")
        held[actuator_of[jid]] = angle
    covered = {m.joint_id for m in mapped} | {int(model.actuator_trnid[a, 0]) for a in held}
    for jid in sorted(set(actuator_of) - covered):
        raise fail("joints", f"the model's actuated joint {model.joint(jid).name!r} is neither mapped in [joints] "
                             "nor held in [hold_deg]")
    return mapped, held


def _joint_id(mujoco, model, name: str) -> int | None:
    jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
    return None if jid < 0 else int(jid)


def _did_you_mean(model, name: str) -> str:
    import difflib

    close = difflib.get_close_matches(name, [model.joint(j).name for j in range(model.njnt)], n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def _is_position_servo(mujoco, model, a: int) -> bool:
    """A position actuator: force = kp (ctrl - q) - kv qdot, i.e. affine bias with biasprm[1] = -kp."""
    kp = float(model.actuator_gainprm[a, 0])
    return (model.actuator_biastype[a] == mujoco.mjtBias.mjBIAS_AFFINE and kp > 0
            and math.isclose(float(model.actuator_biasprm[a, 1]), -kp, rel_tol=1e-9))


def _servo_note(kp: np.ndarray, force_nm: np.ndarray) -> str:
    """The model's own servos in one sentence (the gains gaitbot writes are not simulated on this model)."""
    low, high = float(kp.min()), float(kp.max())
    gains = f"{low:.3g}" if np.isclose(low, high) else f"{low:.3g} to {high:.3g}"
    error = np.degrees(force_nm / kp)
    stiff = f"full torque at {float(error.min()):.3g} deg" if np.isfinite(error).all() else "no force limit"
    return f"the model's own position servos drive the mapped joints: kp {gains} N m/rad, {stiff} (gains written are not simulated)"


class ForeignRobot(SimRobot):
    """A SimRobot (the same interface for the port, the meter, the pusher, the video) on a model by others.

    ``joint_names`` are the mapped gaitbot joints; angles in and out are gaitbot's (sign x the model's)."""

    foreign = True  # its servos are the model's own actuators: the gains a session writes are not simulated

    def __init__(self, config: RobotConfig, rate_hz: float, model_path: str | Path, sim_map: SimMap) -> None:
        from gaitbot.sim.foreign_check import check_kinematics

        self.mujoco = mujoco = import_mujoco()
        self.config, self.support, self.free_pitch, self.planar = config, "free", False, False
        self.model_path = Path(model_path)
        model, self.notes = load_model(mujoco, self.model_path)
        self.frame_s = 1.0 / rate_hz
        self.substeps = substeps_per_frame(self.frame_s, model.opt.timestep)
        if not math.isclose(model.opt.timestep, self.frame_s / self.substeps, rel_tol=1e-6):
            self.notes.append(f"timestep {model.opt.timestep * 1e3:.3g} ms -> {self.frame_s / self.substeps * 1e3:.3g} ms "
                              f"({self.substeps} steps a frame)")
        model.opt.timestep = self.timestep_s = self.frame_s / self.substeps
        self.model, self.data = model, mujoco.MjData(model)
        free = [j for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE]
        if not free:
            raise ForeignModelError(f"--sim-model {self.model_path}: no free-floating body (a free joint): "
                                    "a robot fixed to the world cannot walk")
        self.root_qpos = int(model.jnt_qposadr[free[0]])
        self.torso_body = int(model.jnt_bodyid[free[0]])
        self.mapped, self.held = resolve_joints(mujoco, model, config, sim_map)
        self.joint_names = tuple(m.name for m in self.mapped)
        self.qpos_index = np.array([m.qpos for m in self.mapped])
        self.actuator_index = np.array([m.actuator for m in self.mapped])
        self.signs = np.array([m.sign for m in self.mapped], dtype=float)
        self._kp = model.actuator_gainprm[self.actuator_index, 0].copy()
        forces = np.where(model.actuator_forcelimited[self.actuator_index] > 0,
                          np.abs(model.actuator_forcerange[self.actuator_index]).max(axis=1), np.inf)
        self.stall_nm = forces
        self.full_torque_error_deg = np.degrees(forces / self._kp)
        self.notes.append(_servo_note(self._kp, forces))
        self.imu_body = self._body(sim_map.imu_body, sim_map) if sim_map.imu_body else self.torso_body
        self.floor_geom = _floor_geom(mujoco, model)
        self._find_feet()
        check_kinematics(self, sim_map)
        self._init_state()

    def _body(self, name: str, sim_map: SimMap) -> int:
        bid = self.mujoco.mj_name2id(self.model, self.mujoco.mjtObj.mjOBJ_BODY, name)
        if bid < 0:
            raise SimMapError(sim_map.path, "imu.body", f"the model has no body {name!r}")
        return int(bid)

    def _find_feet(self) -> None:
        """Each foot: the deepest body moved by the side's mapped leg joints (the ankle roll's, in a leg mapped
        right); its soles are every colliding geom on it and the bodies below it."""
        model = self.model
        feet = []
        for side in SIDES:
            bodies = [int(model.jnt_bodyid[m.joint_id]) for kind in LEG_JOINT_KINDS for m in self.mapped
                      if m.name == f"{kind}_{side}"]
            if not bodies:
                raise SimMapError(self.config.path or "robot", "joints", f"no {side} leg joint is mapped")
            feet.append(max(bodies, key=self._depth))
        self.foot_bodies = np.array(feet)
        self.sole_side_of = {}
        for side, body in enumerate(feet):
            below = {b for b in range(model.nbody) if self._descends(b, body)}
            for g in range(model.ngeom):
                if model.geom_bodyid[g] in below and (model.geom_contype[g] or model.geom_conaffinity[g]):
                    self.sole_side_of[g] = side
        self.sole_geoms = np.array(sorted(self.sole_side_of))
        if not all(side in self.sole_side_of.values() for side in range(len(SIDES))):
            raise ForeignModelError(f"--sim-model {self.model_path}: a foot has no colliding geom to stand on")

    def _depth(self, body: int) -> int:
        depth = 0
        while body > 0:
            body, depth = int(self.model.body_parentid[body]), depth + 1
        return depth

    def _descends(self, body: int, ancestor: int) -> bool:
        while body > 0:
            if body == ancestor:
                return True
            body = int(self.model.body_parentid[body])
        return False

    def _init_state(self) -> None:
        self.steps = 0
        self.effort_peak = np.zeros(len(self.mapped))
        self.touch_steps = np.zeros(len(SIDES), dtype=np.int64)
        self.torque_on = np.zeros(len(self.mapped), dtype=bool)
        self.observers = []
        for a, angle in self.held.items():
            self.data.ctrl[a] = angle
        for i in range(len(self.mapped)):
            self.set_torque(i, False)
        self.mujoco.mj_forward(self.model, self.data)

    # --- gaitbot's angles on the model's joints ------------------------------------------------
    def set_goal(self, joint: int, angle_rad: float) -> None:
        self.data.ctrl[self.actuator_index[joint]] = self.signs[joint] * angle_rad

    def goals_rad(self) -> np.ndarray:
        return self.signs * self.data.ctrl[self.actuator_index]

    def joint_angles_rad(self) -> np.ndarray:
        return self.signs * self.data.qpos[self.qpos_index]

    def set_full_torque_error(self, joint: int, error_deg: float) -> None:
        """The model's own servo gains are what is tested: a gain written by the session changes nothing."""

    def place(self, angles_rad: dict[str, float], root_m) -> None:
        """The walk's first pose, upright at the root's x and y, the lowest sole point on the floor."""
        data, model, r = self.data, self.model, self.root_qpos
        for i, name in enumerate(self.joint_names):
            angle = angles_rad.get(name, 0.0)
            data.qpos[self.qpos_index[i]] = self.signs[i] * angle
            data.ctrl[self.actuator_index[i]] = self.signs[i] * angle
        for a, angle in self.held.items():
            data.qpos[model.jnt_qposadr[model.actuator_trnid[a, 0]]] = angle
        root = np.asarray(root_m, dtype=float)
        data.qpos[r:r + 3] = (root[0], root[1], 1.0)
        data.qpos[r + 3:r + 7] = (1.0, 0.0, 0.0, 0.0)
        data.qvel[:] = 0.0
        self.mujoco.mj_kinematics(model, data)
        data.qpos[r + 2] -= self.lowest_sole_z_m()
        self.mujoco.mj_forward(model, data)

    def lowest_sole_z_m(self) -> float:
        """The lowest point of any sole geom (its bounding box, in the geom's frame) above z = 0."""
        data, model = self.data, self.model
        lowest = math.inf
        for g in self.sole_geoms:
            rot_z = data.geom_xmat[g].reshape(3, 3)[2]
            centre, half = model.geom_aabb[g, :3], model.geom_aabb[g, 3:]
            lowest = min(lowest, float(data.geom_xpos[g][2] + rot_z @ centre - np.abs(rot_z) @ half))
        return lowest

    def _step(self, count: int) -> None:
        """``count`` physics steps, keeping each mapped servo's peak |force|; a sole counts as touching for the
        whole chunk if it touches at its end (the model has no touch sensors of gaitbot's)."""
        step, model, data, act = self.mujoco.mj_step, self.model, self.data, self.actuator_index
        peak = np.zeros(len(act))
        for _ in range(count):
            step(model, data)
            np.maximum(peak, np.abs(data.actuator_force[act]), out=peak)
        np.maximum(self.effort_peak, peak / self.stall_nm, out=self.effort_peak)
        touching = np.zeros(len(SIDES), dtype=np.int64)
        for g, _ in self.floor_contacts():
            side = self.sole_side_of.get(g)
            if side is not None:
                touching[side] = 1
        self.touch_steps += touching * count
        self.steps += count
