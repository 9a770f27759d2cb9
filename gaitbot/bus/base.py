"""The transport abstraction: what every servo bus backend offers the streamer.

Modelled on python-can's BusABC: backends differ only below this line.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from enum import StrEnum
from types import MappingProxyType

from gaitbot.servos import model_name_of
from gaitbot.servos.health import HealthReading
from gaitbot.servos.registers import RegisterWrite


class BusError(Exception):
    """A bus operation failed.

    result_code: the SDK's communication result (COMM_* value), or None.
    servo_id: the servo concerned, or None for a whole-bus failure.
    status_error: the servo's status error bits (hardware error byte), 0 when none.
    """

    def __init__(self, message: str, *, result_code: int | None = None, servo_id: int | None = None,
                 status_error: int = 0) -> None:
        super().__init__(message)
        self.result_code = result_code
        self.servo_id = servo_id
        self.status_error = status_error


class PortError(BusError):
    """The serial port cannot be opened, or disappeared."""


class ServoTimeout(BusError):
    """A servo did not answer (after the bounded retries)."""


class ServoLate(ServoTimeout):
    """A servo's status packet arrived after the reply timeout: its answers can no longer be told
    apart from answers to later questions, so the bus stops trusting them."""


class CorruptReplies(ServoTimeout):
    """Most attempts got a damaged status packet (bad checksum/CRC or truncated) from the servo."""


def miss_kind(late: int, damaged: int, silent: int) -> str:
    """What a run of failed exchanges with one servo says of it: ``"late"``, ``"damaged"`` or ``"silent"``,
    whichever most of them were (ties in that order). A few late or damaged replies among many of another
    kind say more about a busy host or one bad moment than about the servo; both the per-frame read-back
    and the blocking reads name a servo by this rule (ServoLate, CorruptReplies, ServoTimeout)."""
    return max((("late", late), ("damaged", damaged), ("silent", silent)), key=lambda kind: kind[1])[0]


class ServoStatusError(BusError):
    """A servo answered with error bits set (overload, overheating, input voltage ...).

    ``fault``: the error in words (gaitbot.servos.status.describe_status_error).
    """

    def __init__(self, message: str, *, fault: str = "", **kwargs) -> None:
        super().__init__(message, **kwargs)
        self.fault = fault


class WrongServoModel(BusError):
    """Servos that answered with another model number than their configured model's: ``wrong`` lists
    (servo id, model number found). Raised before anything is written, so a servo of another model is
    never driven with the configured model's gains, limits and thresholds."""

    def __init__(self, wrong, models, backend: str, port_name: str) -> None:
        self.wrong = [(int(i), int(n)) for i, n in wrong]
        parts = []
        for servo_id, number in self.wrong:
            expected = models[servo_id]
            found = model_name_of(backend, number) or "a model gaitbot does not know"
            parts.append(f"servo {servo_id} is a {found} (model number {number}), the config expects a "
                         f"{expected.name} (model number {expected.model_number})")
        super().__init__(f"wrong servo model on {port_name}: {'; '.join(parts)}; nothing was written "
                         "(fit the configured servo, or describe the robot's real servos in its config)",
                         servo_id=self.wrong[0][0])


class ReadBackOutcome(StrEnum):
    """How a per-frame read-back ended: ANSWERED (a status packet that answers this very request, in
    budget), MISSED (none in budget: the read is abandoned for this frame), DAMAGED (only a damaged status
    packet in budget), SKIPPED (no budget left in the frame: nothing was sent, nothing is counted)."""

    ANSWERED = "answered"
    MISSED = "missed"
    DAMAGED = "damaged"
    SKIPPED = "skipped"


@dataclass(frozen=True)
class ReadBack:
    """One budgeted, non-blocking read of one servo (:meth:`Bus.read_back`), as the session sees it.

    outcome: a :class:`ReadBackOutcome`.
    ticks: present position when answered. data: the register block read (``set_read_back_blocks``),
    when answered. error: the status packet's error byte. late_s: how late this servo's latest
    reply to an abandoned read came, if one came since the last read-back (None: none seen).
    """

    servo_id: int
    outcome: ReadBackOutcome
    ticks: int | None = None
    data: bytes = b""
    error: int = 0
    late_s: float | None = None

    @property
    def answered(self) -> bool:
        return self.outcome == ReadBackOutcome.ANSWERED


class Bus(ABC):
    """A chain of servos on one serial bus: every ability the stream and the bring-up commands use.

    Positions are raw ticks; calibration (angles <-> ticks) lives in the robot room. Optional abilities
    have a default here, so callers never probe for them. ``port_name`` names the port in messages;
    ``open_notes`` say how the port was opened when that differs from the config; ``model_numbers`` holds
    the model number each servo's last ping reported (empty where pings read none).
    """

    port_name: str = "the bus"
    open_notes: tuple[str, ...] | list[str] = ()
    model_numbers: Mapping[int, int] = MappingProxyType({})

    @abstractmethod
    def open(self) -> None: ...

    @abstractmethod
    def close(self) -> None: ...

    @abstractmethod
    def ping(self, servo_id: int) -> bool:
        """True if the servo answers (after bounded retries)."""

    def scan(self, ids: Iterable[int]) -> list[int]:
        """The ids among ``ids`` that answer a ping."""
        return [i for i in ids if self.ping(i)]

    @abstractmethod
    def set_torque(self, ids: Iterable[int], enabled: bool) -> None: ...

    @abstractmethod
    def write_goal_ticks(self, goals: Mapping[int, int]) -> None:
        """Write every goal position of one frame in one sync-write packet: the one goal-writing method
        (a LimitGuard in front checks each goal against its joint's limits first)."""

    @abstractmethod
    def read_present_ticks(self, ids: Iterable[int]) -> dict[int, int]:
        """Present positions (sync read where the protocol has it); reads retry a bounded number of times."""

    def read_health(self, servo_id: int) -> HealthReading:
        """One servo's health block in one READ: present position, temperature, input voltage and (where the
        model has it) present load (gaitbot.servos.health). Retried like a present-position read."""
        raise NotImplementedError(f"{type(self).__name__} cannot read servo health")

    def set_read_back_blocks(self, blocks: dict[int, tuple[int, int]]) -> None:
        """Make ``read_back`` read these registers (servo id -> (address, length), the present position
        inside them) instead of the present position alone; its ``data`` then holds them. In-memory buses,
        which read no registers, ignore it."""

    def read_back(self, servo_id: int, budget_s: float) -> ReadBack:
        """Read one servo back within ``budget_s`` seconds, never longer, never retried (the per-frame
        read of a walk session: docs/bus-faults.md). Backends that talk to servos override this; the
        default asks ``read_present_ticks`` (which may block: for in-memory buses only)."""
        if budget_s <= 0:
            return ReadBack(servo_id, ReadBackOutcome.SKIPPED)
        try:
            ticks = self.read_present_ticks([servo_id]).get(servo_id)
        except ServoTimeout:
            return ReadBack(servo_id, ReadBackOutcome.MISSED)
        return ReadBack(servo_id, ReadBackOutcome.ANSWERED if ticks is not None else ReadBackOutcome.MISSED, ticks)

    def explain_status_error(self, exc: BusError) -> BusError:
        """``exc`` with what the session could not read during the walk (a hardware error register), read
        now that the robot is safe; buses with nothing more to read return it as it is."""
        return exc

    def read_device(self, device_id: int, address: int, length: int, budget_s: float) -> bytes | None:
        """One READ of a device on the bus that is not a servo (the OP3's OpenCR IMU) within ``budget_s``,
        never retried, never waited on beyond it: its bytes, or None when it did not answer in time (or said
        an error). Buses that talk to no device have none: None."""
        return None

    def write_register(self, ids: Iterable[int], address: int, length: int, value: int) -> None:
        """Write a setting (a gain, a lock flag) to each servo, waiting for each one's status packet.

        Not for goal positions (write_goal_ticks, which the LimitGuard checks) nor torque (set_torque).
        Backends that talk to servos implement it; others have nothing to write to."""
        raise NotImplementedError(f"{type(self).__name__} cannot write servo registers")

    def __enter__(self) -> "Bus":
        self.open()
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class BusLayer(Bus):
    """A bus in front of another (``inner``) with the same interface: every ability passes through
    unchanged, and a layer overrides only what it adds (the LimitGuard: its goal check). Written once
    here, beside the Bus it mirrors; tests/bus/test_bus_guard.py checks it passes on every Bus method."""

    def __init__(self, inner: Bus) -> None:
        self.inner = inner

    @property
    def port_name(self) -> str:  # type: ignore[override]
        return self.inner.port_name

    @property
    def open_notes(self):  # type: ignore[override]
        return self.inner.open_notes

    @property
    def model_numbers(self) -> Mapping[int, int]:  # type: ignore[override]
        return self.inner.model_numbers

    def open(self) -> None:
        self.inner.open()

    def close(self) -> None:
        self.inner.close()

    def ping(self, servo_id: int) -> bool:
        return self.inner.ping(servo_id)

    def scan(self, ids: Iterable[int]) -> list[int]:
        return self.inner.scan(ids)

    def set_torque(self, ids: Iterable[int], enabled: bool) -> None:
        self.inner.set_torque(ids, enabled)

    def write_goal_ticks(self, goals: Mapping[int, int]) -> None:
        self.inner.write_goal_ticks(goals)

    def read_present_ticks(self, ids: Iterable[int]) -> dict[int, int]:
        return self.inner.read_present_ticks(ids)

    def read_health(self, servo_id: int) -> HealthReading:
        return self.inner.read_health(servo_id)

    def set_read_back_blocks(self, blocks: dict[int, tuple[int, int]]) -> None:
        self.inner.set_read_back_blocks(blocks)

    def read_back(self, servo_id: int, budget_s: float) -> ReadBack:
        return self.inner.read_back(servo_id, budget_s)

    def read_device(self, device_id: int, address: int, length: int, budget_s: float) -> bytes | None:
        return self.inner.read_device(device_id, address, length, budget_s)

    def write_register(self, ids: Iterable[int], address: int, length: int, value: int) -> None:
        self.inner.write_register(ids, address, length, value)

    def explain_status_error(self, exc: BusError) -> BusError:
        return self.inner.explain_status_error(exc)


__all__ = ["Bus", "BusLayer", "HealthReading", "BusError", "ReadBack", "ReadBackOutcome", "PortError", "ServoTimeout", "ServoLate", "CorruptReplies",
           "ServoStatusError", "RegisterWrite", "WrongServoModel"]
