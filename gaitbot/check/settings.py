"""The settings a recorded run wrote to its servos (gains, the Feetech lock), for ``gaitbot check``.

A session writes each servo's gain register before torque on (``[servo] full_torque_error_deg``,
gaitbot.robot.gains). Those WRITE packets are neither goals nor torque switches; the recording
check accepts them like any well-formed packet to a configured id and lists them here, named after
the servo model's register where gaitbot knows it, so a reader can see what stiffness the robot ran at.
"""

from __future__ import annotations

from dataclasses import dataclass

from gaitbot.servos import wire
from gaitbot.servos.models import ServoModel


@dataclass(frozen=True)
class SettingWrite:
    """One WRITE instruction to a setting register: where in the recording, which servo, what value."""

    line_no: int
    t_s: float
    servo_id: int
    address: int
    length: int
    value: int
    register: str  # the register's name, or "address N" when gaitbot does not know it


def setting_write(line_no: int, t_s: float, packet, model: ServoModel) -> SettingWrite | None:
    """The setting a tx packet writes (None for anything else: goals, torque, reads, sync packets).

    ``packet`` is a checksum-valid ParsedPacket (gaitbot.bus.recording)."""
    if packet.instruction != wire.INST_WRITE or packet.address is None or not packet.data:
        return None
    address, length = packet.address, len(packet.data)
    if model.command_register_touched(address, length) is not None:
        return None
    value = int.from_bytes(packet.data, model.byte_order)
    return SettingWrite(line_no, t_s, packet.packet_id, address, length, value, _register_name(model, address))


def _register_name(model: ServoModel, address: int) -> str:
    gain = model.gain
    if gain is not None:
        if address in gain.addresses:
            return gain.name
        for before_address, _length, _value, name in gain.before:
            if address == before_address:
                return name
    return f"address {address}"


def describe_settings(settings: tuple[SettingWrite, ...], models: dict[int, ServoModel]) -> list[str]:
    """One line per register and value: the ids it went to, the lines, and the stiffness a gain gives."""
    groups: dict[tuple[str, int, int, int], list[SettingWrite]] = {}
    for s in settings:
        groups.setdefault((s.register, s.address, s.length, s.value), []).append(s)
    lines = []
    for (register, address, length, value), writes in groups.items():
        ids = ", ".join(str(i) for i in sorted({w.servo_id for w in writes}))
        model = models.get(writes[0].servo_id)
        gain = model.gain if model is not None else None
        stiffness = ""
        if gain is not None and address in gain.addresses:
            stiffness = f" (full torque at {gain.full_torque_error_deg(value):.3g} deg)"
        lines.append(f"{register} ({address}, {length} B) = {value}{stiffness} to ids {ids}, "
                     f"lines {writes[0].line_no}..{writes[-1].line_no}")
    return lines
