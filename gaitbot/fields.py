"""The one field-checked reader of files a person writes by hand (robot configs, terrain courses).

Every problem is ONE line naming the file, the dotted field and what is wrong and what is allowed::

    config/xl430-biped.toml: joints.knee_pitch_left.min_deg: 120.0 is above max_deg 110.0

Unknown keys are errors too (with a did-you-mean): they are usually typos (``max_velocity_dsp``)
that would otherwise silently fall back to a default. Each format subclasses :class:`FieldError`
(so its errors have a name of their own) and reads its sections through :class:`Fields`.
"""

from __future__ import annotations

import difflib
import math
import re
from pathlib import Path
from typing import Any

from gaitbot.errors import UserError

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]


class FieldError(UserError, ValueError):
    """A file is unusable. The message is one line: ``<file>: <field>: <what is wrong>``.

    ``path``, ``field`` and ``reason`` hold the three parts for callers that want them apart.
    """

    def __init__(self, path: str | Path, field: str, reason: str) -> None:
        self.path = str(path)
        self.field = field
        self.reason = " ".join(str(reason).split())  # one line, whatever the reason held
        super().__init__(f"{self.path}: {field}: {self.reason}")

    @classmethod
    def unreadable(cls, path: Path, exc: BaseException) -> "FieldError":
        """The file cannot be read at all."""
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        return cls(path, "file", f"cannot read ({reason})")

    @classmethod
    def not_toml(cls, path: Path, exc: Exception) -> "FieldError":
        """A TOML syntax error, named by its line."""
        message = str(exc)
        match = re.search(r"\(at line (\d+), column (\d+)\)", message)
        where = f"line {match.group(1)}" if match else "file"
        reason = re.sub(r"\s*\(at line \d+, column \d+\)", "", message)
        if match:
            reason += f" (column {match.group(2)})"
        return cls(path, where, f"TOML syntax error: {reason}")


#: A hand-written TOML file larger than this is refused before parsing (the shipped ones are ~3 KB).
MAX_TOML_CHARS = 1_000_000
MAX_TOML_LINE_CHARS = 10_000
#: No integer field of a hand-written file means anything beyond this (ids, ticks, baud rates).
MAX_INTEGER = 2**53


#: The largest file of each kind gaitbot reads (bytes): far beyond any real one, far below the machine.
MAX_FILE_BYTES = 256 * 2**20


def read_user_file(path: str | Path, max_bytes: int = MAX_FILE_BYTES) -> bytes:
    """The bytes of a file a user named, read whole: it must be a regular file (a FIFO would block, a device
    such as /dev/zero never ends) of at most ``max_bytes``. OSError (with a ``strerror`` for people) otherwise."""
    import errno
    import os
    import stat

    path = Path(path)
    info = os.stat(path)  # FileNotFoundError, PermissionError, ELOOP ... as they are
    if stat.S_ISDIR(info.st_mode):
        raise IsADirectoryError(errno.EISDIR, "is a directory", str(path))
    if not stat.S_ISREG(info.st_mode):
        raise OSError(errno.EINVAL, "not a regular file (a FIFO, a device or a socket)", str(path))
    if info.st_size > max_bytes:
        raise OSError(errno.EFBIG, f"{info.st_size} bytes, larger than the {max_bytes} bytes such a file may have",
                      str(path))
    with open(path, "rb") as f:
        data = f.read(max_bytes + 1)
    if len(data) > max_bytes:
        raise OSError(errno.EFBIG, f"larger than the {max_bytes} bytes such a file may have", str(path))
    return data


def read_toml(path: str | Path, error: type[FieldError]) -> dict:
    """The parsed TOML file; ``error`` (a FieldError subclass) for a file that cannot be read or parsed."""
    path = Path(path)
    try:
        text = read_user_file(path, MAX_TOML_CHARS).decode("utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise error.unreadable(path, exc) from None
    if len(text) > MAX_TOML_CHARS:
        raise error(path, "file", f"{len(text)} characters, more than a hand-written file holds "
                                  f"(at most {MAX_TOML_CHARS})")
    for number, line in enumerate(text.splitlines(), start=1):
        if len(line) > MAX_TOML_LINE_CHARS:  # the TOML parser is slow on some very long lines (deep dotted keys)
            raise error(path, f"line {number}", f"{len(line)} characters, more than a hand-written line holds "
                                                f"(at most {MAX_TOML_LINE_CHARS})")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error.not_toml(path, exc) from None
    except ValueError as exc:  # e.g. an integer beyond Python's 4300-digit conversion limit
        raise error(path, "file", f"TOML value not readable: {exc}") from None
    except (RecursionError, MemoryError):
        raise error(path, "file", "nested too deeply (arrays or tables inside each other beyond what a config "
                                  "holds)") from None


def kind(value: Any) -> str:
    """A short description of a TOML value for error messages."""
    if isinstance(value, bool):
        return f"boolean {str(value).lower()}"
    if isinstance(value, str):
        return f"string {value!r}"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return "an array"
    if isinstance(value, int) and abs(value) > 10**30:
        return f"an integer of about {int(abs(value).bit_length() * 0.30103) + 1} digits"
    if isinstance(value, (int, float)):
        return f"number {value}"
    return type(value).__name__


class Fields:
    """Field-by-field reading with the field's dotted name at hand for the error message.

    ``field`` arguments are the dotted name of the table a key sits in ("" at the top level)."""

    def __init__(self, path: str | Path, error: type[FieldError]) -> None:
        self.path = Path(path)
        self.error = error

    def fail(self, field: str, reason: str) -> FieldError:
        return self.error(self.path, field, reason)

    def table(self, parent: dict, key: str, field: str, allowed: tuple[str, ...]) -> dict:
        """A required table whose keys must be among ``allowed``."""
        if key not in parent:
            raise self.fail(field, f"missing section [{field}]")
        value = parent[key]
        if not isinstance(value, dict):
            raise self.fail(field, f"must be a table [{field}], got {kind(value)}")
        self.no_unknown_keys(value, field, allowed)
        return value

    def optional_table(self, parent: dict, key: str, field: str, allowed: tuple[str, ...]) -> dict:
        """An optional table: {} when absent, otherwise checked like a required one."""
        return self.table(parent, key, field, allowed) if key in parent else {}

    def tables(self, parent: dict, key: str, allowed: tuple[str, ...]) -> list[dict]:
        """An optional array of tables (``[[key]]``), each checked for unknown keys as ``key[n]``."""
        value = parent.get(key, [])
        if not isinstance(value, list) or not all(isinstance(t, dict) for t in value):
            raise self.fail(key, f"write each {key} as a [[{key}]] table")
        for n, t in enumerate(value, start=1):
            self.no_unknown_keys(t, f"{key}[{n}]", allowed)
        return value

    def no_unknown_keys(self, table: dict, field: str, allowed: tuple[str, ...]) -> None:
        for key in table:
            if key not in allowed:
                close = difflib.get_close_matches(key, allowed, n=1)
                hint = f"did you mean {close[0]!r}? " if close else ""
                prefix = f"{field}.{key}" if field else key
                raise self.fail(prefix, f"unknown key ({hint}allowed: {', '.join(allowed)})")

    def require(self, table: dict, key: str, field: str, what: str):
        if key not in table:
            raise self.fail(f"{field}.{key}", f"missing (expected {what})")
        return table[key]

    def number(self, table: dict, key: str, field: str, *, positive: bool = False,
               non_negative: bool = False, default: float | None = None,
               within: tuple[float, float, str] | None = None) -> float:
        """A finite number (ints accepted, booleans not); ``default`` when absent, if given; ``within``
        = (lowest, highest, unit) bounds it, both ends included."""
        what = "a positive number" if positive else "a number >= 0" if non_negative else "a number"
        if key not in table and default is not None:
            return default
        value = self.require(table, key, field, what)
        return self.check_number(value, f"{field}.{key}", positive=positive, non_negative=non_negative,
                                 within=within)

    def check_number(self, value: Any, name: str, *, positive: bool = False, non_negative: bool = False,
                     within: tuple[float, float, str] | None = None) -> float:
        """``value`` (found at dotted ``name``) as a float, or the error saying what is allowed."""
        what = "a positive number" if positive else "a number >= 0" if non_negative else "a number"
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(name, f"must be {what}, got {kind(value)}")
        try:
            number = float(value)
        except OverflowError:
            raise self.fail(name, f"must be a finite number, got an integer of about "
                                  f"{int(abs(value).bit_length() * 0.30103) + 1} digits") from None
        if not math.isfinite(number):
            raise self.fail(name, f"must be a finite number, got {value}")
        if positive and number <= 0:
            raise self.fail(name, f"must be a positive number, got {value}")
        if non_negative and number < 0:
            raise self.fail(name, f"must be >= 0, got {value}")
        if within is not None:
            low, high, unit = within
            if not low <= number <= high:
                raise self.fail(name, f"{number:g} is outside the allowed {low:g}..{high:g}{' ' + unit if unit else ''}")
        return number

    def integer(self, table: dict, key: str, field: str, what: str = "an integer") -> int:
        value = self.require(table, key, field, what)
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(f"{field}.{key}", f"must be {what}, got {kind(value)}")
        if abs(value) > MAX_INTEGER:
            raise self.fail(f"{field}.{key}", f"must be {what}, got an integer of about "
                                                  f"{int(abs(value).bit_length() * 0.30103) + 1} digits")
        return value

    def string(self, table: dict, key: str, field: str, what: str = "a non-empty string") -> str:
        value = self.require(table, key, field, what)
        if not isinstance(value, str) or not value.strip():
            raise self.fail(f"{field}.{key}", f"must be {what}, got {kind(value)}")
        return value

    def boolean(self, table: dict, key: str, field: str, default: bool) -> bool:
        value = table.get(key, default)
        if not isinstance(value, bool):
            raise self.fail(f"{field}.{key}", f"must be true or false, got {kind(value)}")
        return value
