"""The simulation bus: the real Dynamixel/Feetech backend and SDK packet code on a port whose servos
are the simulated robot's joints.

SimPort is the mock port (gaitbot.bus.dry_run: parses every instruction packet and answers as the
servos would) with physics behind the control tables instead of ideal servos:

* before each packet is handled, the physics advances to the clock's present time, so a goal
  takes effect at the moment the streamer sends it and holds until the next one;
* a goal-position write becomes the joint's actuator target (ticks -> angle by the robot's
  calibration, the inverse of what the streamer did);
* a torque-enable write switches the joint's servo on or off;
* a write to the model's gain register (Position P Gain, Compliance Slope, P coefficient) sets the
  joint's stiffness from the register's bytes (GainRegister.full_torque_error_deg, gaitbot.servos.models); the
  table starts with the factory value, so a session that writes no gain walks at factory stiffness;
* a present-position read answers the simulated joint angle (angle -> ticks by the calibration).

Joints the model does not have (held joints such as the ax12a-biped's hip roll on the planar boom
model) stay ideal mock servos. Everything else (pings, checksums, status packets, the recorder) is the mock's, so a
``--sim --record`` recording holds exactly the packets a real run would send.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from gaitbot.bus.base import Bus
from gaitbot.bus.factory import bus_class
from gaitbot.bus.recording import BusRecorder
from gaitbot.bus.dry_run import DryRunPort
from gaitbot.robot.calibration import angle_rad_to_ticks, ticks_to_angle_rad
from gaitbot.robot.config import RobotConfig
from gaitbot.servos import opencr
from gaitbot.servos.registers import overlaps
from gaitbot.sim.imu import SimImu
from gaitbot.sim.physics import SimRobot


class SimPort(DryRunPort):
    """A DryRunPort whose walking servos are ``robot``'s joints, on the time ``now()`` tells (seconds)."""

    def __init__(self, config: RobotConfig, robot: SimRobot, now: Callable[[], float], port_name: str = "sim",
                 imu_seed: int = 0, imu_fault: str | None = None) -> None:
        super().__init__(config.bus.backend, config.bus.protocol, config.models_by_id, port_name=port_name,
                         baudrate=config.bus.baudrate)
        self.robot = robot
        self.now = now
        self.imu = self.imu_id = None
        if config.imu.source == "opencr":  # the OP3's OpenCR on the same bus, its IMU the simulated one
            self.imu_id = config.imu.device_id
            self.tables[self.imu_id] = opencr.initial_table()
            self.imu = SimImu(robot, config.imu, self.tables[self.imu_id], robot.imu_body, imu_seed, imu_fault)
            robot.observers.append(self.imu)
        walking = [config.joint(name) for name in robot.joint_names]  # the joints the model has, in its order
        self.joint_of = {j.id: i for i, j in enumerate(walking)}
        self._ids = [j.id for j in walking]
        self._calibration = {j.id: (j.zero_tick, j.direction, j.model.ticks_per_rad) for j in walking}
        self._zero, self._direction, self._per_rad = (np.array(v, dtype=float) for v in zip(
            *(self._calibration[i] for i in self._ids)))
        self._tick_range = (np.array([j.model.min_tick for j in walking]), np.array([j.model.max_tick for j in walking]))

    def writePort(self, packet) -> int:  # noqa: N802 (SDK name)
        self.robot.advance_to(self.now())
        return super().writePort(packet)

    def _read(self, frame) -> None:
        self._refresh_present()
        super()._read(frame)

    def _sync_read(self, frame) -> None:
        self._refresh_present()
        super()._sync_read(frame)

    def _refresh_present(self) -> None:
        """Write the simulated joint angles, as ticks, into the present-position registers."""
        ticks = np.clip(angle_rad_to_ticks(self.robot.joint_angles_rad(), self._zero, self._direction, self._per_rad),
                        *self._tick_range)
        for servo_id, tick in zip(self._ids, ticks.tolist()):
            model = self.models[servo_id]
            start = model.addr_present_position
            self.tables[servo_id][start:start + model.len_present_position] = \
                tick.to_bytes(model.len_present_position, model.byte_order)

    def hears(self, servo_id: int) -> bool:
        if servo_id == self.imu_id:
            return self.imu.answering
        return super().hears(servo_id)

    def _targets(self, packet_id: int) -> list[int]:
        """The IMU device answers what is sent to its id (a broadcast ping finds the servos only)."""
        return [i for i in super()._targets(packet_id) if i != self.imu_id or packet_id == self.imu_id]

    def _ping(self, frame) -> None:
        if frame.packet_id == self.imu_id and self.imu is not None and self.imu.answering:
            self._reply(self.imu_id, bytes(self.tables[self.imu_id][0:2]) + bytes([opencr.OPENCR_OP3_FIRMWARE]))
            return
        super()._ping(frame)

    def _store(self, servo_id: int, address: int, data: bytes) -> None:
        if servo_id == self.imu_id:  # a setting of the device (LED, IMU Control): kept, no effect on the physics
            self.tables[servo_id][address:address + len(data)] = data
            return
        joint = self.joint_of.get(servo_id)
        if joint is None:
            super()._store(servo_id, address, data)  # a held joint: an ideal servo
            return
        table, model = self.tables[servo_id], self.models[servo_id]
        table[address:address + len(data)] = data
        if overlaps(address, len(data), model.addr_goal_position, model.len_goal_position):
            start = model.addr_goal_position
            ticks = int.from_bytes(table[start:start + model.len_goal_position], model.byte_order)
            self.robot.set_goal(joint, float(ticks_to_angle_rad(ticks, *self._calibration[servo_id])))
        if overlaps(address, len(data), model.addr_torque_enable, 1):
            self.robot.set_torque(joint, bool(table[model.addr_torque_enable]))
        gain = model.gain
        if gain is not None and any(overlaps(address, len(data), a, gain.length) for a in gain.addresses):
            # One stiffness per joint in a planar model: the softer of the registers (AX: CW and CCW slope).
            values = [int.from_bytes(table[a:a + gain.length], model.byte_order) for a in gain.addresses]
            self.robot.set_full_torque_error(joint, max(gain.full_torque_error_deg(v) for v in values))


def make_sim_bus(config: RobotConfig, robot: SimRobot, now: Callable[[], float],
                 recorder: BusRecorder | None = None, imu_seed: int = 0, imu_fault: str | None = None) -> Bus:
    """The robot's own bus class (Dynamixel or Feetech, with its SDK) on a SimPort whose physics follows
    ``now()`` (the streamer's clock, e.g. ``VirtualClock().now``).

    Like a dry run, but the servos are ``robot``'s joints; the bus is not opened here."""
    cls = bus_class(config.bus.backend)
    handler = SimPort(config, robot, now, imu_seed=imu_seed, imu_fault=imu_fault)
    if recorder is not None:
        handler = recorder.wrap(handler, backend=config.bus.backend, protocol=config.bus.protocol,
                                baudrate=config.bus.baudrate, models=config.models_by_id)
    return cls("sim", config.bus.baudrate, config.bus.protocol, config.models_by_id, port_handler=handler, clock=now)
