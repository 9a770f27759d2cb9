"""The transport abstraction: what every servo bus backend offers the streamer.

Modelled on python-can's BusABC: backends differ only below this line.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

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
    """Every attempt got a damaged status packet (bad checksum/CRC or truncated) from the servo."""


class ServoStatusError(BusError):
    """A servo answered with error bits set (overload, overheating, input voltage ...).

    ``fault``: the error in words (gaitbot.servos.status.describe_status_error).
    """

    def __init__(self, message: str, *, fault: str = "", **kwargs) -> None:
        super().__init__(message, **kwargs)
        self.fault = fault


@dataclass(frozen=True)
class ReadBack:
    """One budgeted, non-blocking read of one servo (:meth:`Bus.read_back`), as the session sees it.

    outcome: "answered" (a status packet that answers this very request, in budget), "missed" (none
    in budget: the read is abandoned for this frame), "damaged" (only a damaged status packet in
    budget), "skipped" (no budget left in the frame: nothing was sent, nothing is counted).
    ticks: present position when answered. data: the register block read (``set_read_back_blocks``),
    when answered. error: the status packet's error byte. late_s: how late this servo's latest
    reply to an abandoned read came, if one came since the last read-back (None: none seen).
    """

    servo_id: int
    outcome: str
    ticks: int | None = None
    data: bytes = b""
    error: int = 0
    late_s: float | None = None

    @property
    def answered(self) -> bool:
        return self.outcome == "answered"


class Bus(ABC):
    """A chain of servos on one serial bus.

    Positions are raw ticks; calibration (angles <-> ticks) lives in the robot room.
    """

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
        """Write every goal position of one frame in one sync-write packet."""

    def send_goal_ticks(self, goals: Mapping[int, int]) -> None:
        """Write goals already checked by the caller (the LimitGuard, whose limits lie inside the servos'
        tick ranges), so that each goal is checked once on the 60 Hz path. Backends that check goals
        themselves in write_goal_ticks override this to skip that check."""
        self.write_goal_ticks(goals)

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
            return ReadBack(servo_id, "skipped")
        try:
            ticks = self.read_present_ticks([servo_id]).get(servo_id)
        except ServoTimeout:
            return ReadBack(servo_id, "missed")
        return ReadBack(servo_id, "answered" if ticks is not None else "missed", ticks)

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


__all__ = ["Bus", "HealthReading", "BusError", "ReadBack", "PortError", "ServoTimeout", "ServoLate", "CorruptReplies",
           "ServoStatusError", "RegisterWrite"]
