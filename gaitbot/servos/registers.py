"""Control-table registers as data: where a register is, how wide, and what it holds from the factory."""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple


class Register(NamedTuple):
    """One control-table register: byte ``address``, ``size`` in bytes, ``factory`` value (None: not emulated)."""

    address: int
    size: int
    factory: int | None = None


#: A servo series' control table: register name (the maker's, e.g. "Goal Position") -> Register.
ControlTable = dict[str, Register]


@dataclass(frozen=True)
class RegisterWrite:
    """A setting a session writes to servos before torque goes on: ``value`` as ``length`` bytes (each
    servo's byte order) at control-table ``address`` of every servo in ``ids``; ``name`` says what the
    register is, for messages."""

    ids: tuple[int, ...]
    address: int
    length: int
    value: int
    name: str = ""


def overlaps(address: int, length: int, start: int, size: int) -> bool:
    """True when the bytes ``address .. address + length`` touch the register at ``start .. start + size``."""
    return address < start + size and start < address + length
