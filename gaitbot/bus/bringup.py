"""Bring-up on the wire: survey a bus at every baud rate, give one servo its id and baud rate, and describe
what a servo says about itself (gaitbot setup, gaitbot scan). The people's side (prompts, tables) is in
gaitbot/app/setup.py and scan.py; docs/bring-up.md tells the whole story.

Giving a servo its id and baud rate (:func:`assign_id_and_baud`) writes exactly these registers, in this
order, and nothing else (the e-Manual's "ID" and "Baud Rate" control-table entries; LeRobot's
``setup_motor`` does the same):

1. Torque Enable = 0 (EEPROM is writable only with torque off on Dynamixel; Feetech is not documented
   either way, so it is done there too), confirmed;
2. Feetech only: Lock = 0, confirmed (with the lock on, EEPROM writes take effect but are lost at
   power-off);
3. ID = the new id, at the old id, not waited for (whether the servo answers as its old or its new self
   is not documented); then a PING at the new id confirms it (if the old id answers instead, the write
   was lost and is sent again, as in step 4);
4. Baud Rate = the new rate's register value, at the new id, not waited for (the answer may come at either
   rate); once the write has left the port (and 10 ms more) the host switches to the new rate and PINGs;
   if only the old rate answers, the servo never heard the write (it is sent unconfirmed, so noise or a
   busy host that switched too soon loses it) and it is written again, up to WRITE_TRIES times;
5. read back ID, Baud Rate and Model Number at the new id and rate; Feetech: Lock = 1 again (its
   power-on state; the id and rate written while it was 0 are saved).
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass, field

from gaitbot.bus.base import BusError, ServoTimeout
from gaitbot.bus.probe import ProbeBus, ProbeResult, ServoFound
from gaitbot.servos import baud_rates, baud_register_value
from gaitbot.servos.health import HealthReading, decode_health, health_block
from gaitbot.servos.models import ServoModel
from gaitbot.servos.status import describe_status_error, hardware_error_bits


#: ID or Baud Rate writes sent before setup gives up on a servo that still answers as its old self.
WRITE_TRIES = 3


class SetupFailed(BusError):
    """A servo did not take its new id or baud rate (a write it never heard, or a read-back that disagrees)."""


def survey(probe: ProbeBus, baudrates: Sequence[int], on_baud: Callable[[ProbeResult], None] | None = None,
           on_ping: Callable[[int], None] | None = None,
           expected: Mapping[int, Collection[int]] | None = None) -> list[ProbeResult]:
    """Search the bus at each rate in turn: every servo that answers, and the damaged replies, per rate
    (``on_baud`` after each rate, ``on_ping`` after each PING, ``expected`` {rate: ids a config puts
    there}: ProbeBus.search)."""
    results = []
    for rate in baudrates:
        probe.set_baudrate(rate)
        result = probe.search(on_ping=on_ping, expected=(expected or {}).get(rate, ()))
        results.append(result)
        if on_baud is not None:
            on_baud(result)
    return results


@dataclass(frozen=True)
class Assignment:
    """What setup did to one servo: where it was, where it is now, and the writes (register, value) it sent."""

    before: ServoFound
    servo_id: int
    baudrate: int
    writes: tuple[tuple[str, int], ...]


def assign_id_and_baud(probe: ProbeBus, found: ServoFound, model: ServoModel, new_id: int,
                       new_baudrate: int) -> Assignment:
    """Give the servo ``found`` the id ``new_id`` and the rate ``new_baudrate`` (the module docstring's steps),
    then read both back. ValueError when the model cannot hold the rate; SetupFailed when the servo never
    hears a write or the read-back disagrees; ServoTimeout when the servo stops answering."""
    value = baud_register_value(model.name, new_baudrate)
    if value is None:
        rates = ", ".join(f"{r:,}" for r in baud_rates(model.name).values())
        raise ValueError(f"a {model.name} cannot run at {new_baudrate:,} baud (its Baud Rate register holds {rates})")
    table = model.control_table
    torque, servo_id_reg, baud = table["Torque Enable"], table["ID"], table["Baud Rate"]
    lock = table.get("Lock")  # Feetech's EEPROM lock (Dynamixel tables have none)
    writes: list[tuple[str, int]] = []
    probe.set_baudrate(found.baudrate)
    servo_id = found.servo_id

    def write(name: str, address: int, data: int, *, confirm: bool = True, at: int | None = None) -> None:
        error = probe.write(servo_id if at is None else at, address, bytes([data]), confirm=confirm)
        writes.append((name, data))
        if error:
            words = describe_status_error(model.family, probe.protocol, error, model_name=model.name)
            raise SetupFailed(f"servo {servo_id} refused writing {name} = {data}: {words}", servo_id=servo_id,
                              status_error=error)

    write("Torque Enable", torque.address, 0)
    if lock is not None:
        write("Lock", lock.address, 0)
    if new_id != servo_id:
        heard = _until_heard(lambda: write("ID", servo_id_reg.address, new_id, confirm=False),
                             lambda: probe.ping(new_id), lambda: probe.ping(servo_id))
        if heard is None:
            raise SetupFailed(f"wrote id {new_id} to servo {servo_id} at {found.baudrate:,} baud, but nothing answers "
                              f"at id {new_id}; run setup again for this joint", servo_id=servo_id)
        if heard is False:
            raise SetupFailed(f"servo {servo_id} still answers at id {servo_id} after {WRITE_TRIES} writes of its "
                              f"ID ({new_id}); check its cable and run setup again for this joint", servo_id=servo_id)
        servo_id = new_id
    if new_baudrate != found.baudrate:
        def send_rate() -> None:
            probe.set_baudrate(found.baudrate)
            write("Baud Rate", baud.address, value, confirm=False)
            probe.drain()  # the write must leave at the old rate before the host switches

        def answers_at(rate: int) -> bool:
            probe.set_baudrate(rate)
            return probe.ping(servo_id)

        heard = _until_heard(send_rate, lambda: answers_at(new_baudrate), lambda: answers_at(found.baudrate))
        probe.set_baudrate(new_baudrate)  # silent at both rates (None): the read-back below says so
        if heard is False:
            raise SetupFailed(f"servo {servo_id} still answers at {found.baudrate:,} baud after {WRITE_TRIES} "
                              f"writes of its Baud Rate ({value}, {new_baudrate:,} baud); check its cable and run "
                              "setup again for this joint", servo_id=servo_id)
    try:
        got_id = probe.read(servo_id, servo_id_reg.address, 1)[0][0]
        got_baud = probe.read(servo_id, baud.address, 1)[0][0]
    except ServoTimeout:
        raise SetupFailed(f"servo {new_id} does not answer at {new_baudrate:,} baud after its baud rate was written; "
                          "find it with gaitbot scan and run setup again for this joint", servo_id=new_id) from None
    number = probe.model_number(servo_id)
    if (got_id, got_baud, number) != (new_id, value, model.model_number):
        raise SetupFailed(f"read back id {got_id}, baud rate register {got_baud} and model number {number}; expected "
                          f"{new_id}, {value} ({new_baudrate:,} baud) and {model.model_number} ({model.name})",
                          servo_id=servo_id)
    if lock is not None:
        write("Lock", lock.address, 1)
    return Assignment(found, servo_id, new_baudrate, tuple(writes))


def _until_heard(send: Callable[[], None], heard: Callable[[], bool], still_old: Callable[[], bool]) -> bool | None:
    """Send an unconfirmed write until the servo answers as its new self (``heard``): True. When it answers
    as its old self (``still_old``) it never heard the write, which is sent again, WRITE_TRIES in all
    (False: it never did); None when it answers as neither."""
    for _ in range(WRITE_TRIES):
        send()
        if heard():
            return True
        if not still_old():
            return None
    return False


@dataclass(frozen=True)
class ServoReport:
    """What a servo says about itself (gaitbot scan): firmware, health, torque, hardware errors in words."""

    found: ServoFound
    firmware: str | None = None
    health: HealthReading | None = None
    torque_on: bool | None = None
    errors: tuple[str, ...] = ()
    problems: tuple[str, ...] = field(default_factory=tuple)  # reads that failed


def describe_servo(probe: ProbeBus, found: ServoFound) -> ServoReport:
    """Read a found servo's firmware, health block, torque and hardware error register (reads only)."""
    model = found.model
    if model is None:
        return ServoReport(found, problems=(f"model number {found.model_number} is not a model gaitbot knows",))
    table, servo_id, problems = model.control_table, found.servo_id, []
    probe.set_baudrate(found.baudrate)

    def read(name: str, length: int | None = None) -> tuple[bytes, int] | None:
        register = table[name]
        try:
            return probe.read(servo_id, register.address, length or register.size)
        except ServoTimeout as exc:
            problems.append(f"{name}: {exc}")
            return None

    firmware = None
    if "Firmware Version" in table:
        got = read("Firmware Version")
        firmware = str(got[0][0]) if got else None
    else:
        got = read("Firmware Major Version", 2)
        firmware = f"{got[0][0]}.{got[0][1]}" if got else None
    block = health_block(model)
    health, status_error = None, 0
    try:
        data, status_error = probe.read(servo_id, block.address, block.length)
        health = decode_health(block, servo_id, data)
    except ServoTimeout as exc:
        problems.append(f"health: {exc}")
    got = read("Torque Enable")
    torque = bool(got[0][0]) if got else None
    errors: list[str] = []
    register = table.get("Hardware Error Status") or table.get("Servo Status")
    if register is not None:
        got = read("Hardware Error Status" if "Hardware Error Status" in table else "Servo Status")
        if got and got[0][0]:
            names = hardware_error_bits(model.name)
            errors = [name for bit, name in names.items() if got[0][0] & bit] or [f"0x{got[0][0]:02X}"]
    elif status_error:  # AX: the errors come in every status packet
        errors = describe_status_error(model.family, probe.protocol, status_error, model_name=model.name).split(", ")
    return ServoReport(found, firmware, health, torque, tuple(errors), tuple(problems))
