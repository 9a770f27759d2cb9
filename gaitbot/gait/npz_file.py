"""Reading a user's ``.npz`` (a trajectory, an eigen-gait model) without trusting it.

``numpy.load`` allocates whatever an array's header claims, takes a string, object, complex or 0-d
array as readily as a table of numbers, and raises a dozen exception types on a damaged zip. Here each
array's header is read first (shape and dtype, no data), its size is bounded, pickles are refused, and
only then is it loaded; every problem is one :class:`ValueError` naming the array, which the readers
turn into their own one-line error naming the file.
"""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np

from gaitbot.fields import read_user_file

#: Elements one array of a user's .npz may hold (a one-hour 200 Hz trajectory has 720,000 x 9).
MAX_ELEMENTS = 20_000_000
#: Kinds of arrays a numeric field may be: booleans, integers, floats (no complex, strings, objects).
NUMERIC_KINDS = "biuf"
#: Kinds of arrays a file may hold at all: numbers, and text (joint names, a model's kind and robot).
READABLE_KINDS = NUMERIC_KINDS + "U"
#: Bytes one array may take once read: MAX_ELEMENTS float64s. Checked on the header, before any data is read.
MAX_BYTES = MAX_ELEMENTS * 8
#: The longest text one element may hold (a joint or robot name), in characters.
MAX_TEXT_CHARS = 256


class NpzProblem(ValueError):
    """One line: what is wrong with which array of the file."""


_READ_ERRORS = (ValueError, EOFError, OSError, zipfile.BadZipFile, zipfile.LargeZipFile, TypeError, OverflowError,
                MemoryError, UnicodeDecodeError, SyntaxError, RuntimeError)


def _checked_header(archive: zipfile.ZipFile, member: zipfile.ZipInfo, key: str) -> None:
    """The array's header (shape and dtype, no data): its kind readable, its size within MAX_BYTES."""
    with archive.open(member) as f:
        version = np.lib.format.read_magic(f)
        if version == (1, 0):
            shape, _fortran, dtype = np.lib.format.read_array_header_1_0(f)
        else:
            shape, _fortran, dtype = np.lib.format.read_array_header_2_0(f)
    if dtype.hasobject:
        raise NpzProblem(f"array {key!r} holds Python objects (pickles are not read)")
    if dtype.kind not in READABLE_KINDS:
        raise NpzProblem(f"array {key!r} holds {_kind(dtype)} ({dtype}); a trajectory or model holds numbers "
                         f"and names")
    if dtype.kind == "U" and dtype.itemsize > 4 * MAX_TEXT_CHARS:
        raise NpzProblem(f"array {key!r} holds text of {dtype.itemsize // 4} characters an element, more than "
                         f"the {MAX_TEXT_CHARS} a name may have")
    count = int(np.prod(shape, dtype=object)) if shape else 1
    if count > MAX_ELEMENTS or count * dtype.itemsize > MAX_BYTES:
        raise NpzProblem(f"array {key!r} claims {count} elements of {dtype.itemsize} bytes, more than the "
                         f"{MAX_ELEMENTS} elements or {MAX_BYTES // 2**20} MB such a file may hold")


def read_npz(path: str | Path, only: tuple[str, ...] | None = None) -> dict[str, np.ndarray]:
    """Every array of the file (or those named in ``only``), after every array's header was checked for
    its kind and size, whatever its name: no data is read before all headers passed.

    Raises OSError (the file cannot be read: missing, a directory, a device) or NpzProblem."""
    import io

    data = read_user_file(path)
    try:
        archive = zipfile.ZipFile(io.BytesIO(data))
        members = archive.infolist()  # every member, a repeated name too
    except (zipfile.BadZipFile, zipfile.LargeZipFile, ValueError, EOFError, OSError) as exc:
        raise NpzProblem(f"not a readable .npz (not a zip archive: {exc})") from None
    keys = [(member, member.filename[:-4] if member.filename.endswith(".npy") else member.filename)
            for member in members]
    for member, key in keys:
        try:
            _checked_header(archive, member, key)
        except NpzProblem:
            raise
        except _READ_ERRORS as exc:
            reason = " ".join(str(exc).split())[:200]
            raise NpzProblem(f"array {key!r} is not readable ({type(exc).__name__}: {reason})") from None
    arrays: dict[str, np.ndarray] = {}
    for member, key in keys:
        if only is not None and key not in only:
            continue
        try:
            with archive.open(member) as f:
                arrays[key] = np.lib.format.read_array(f, allow_pickle=False)
        except _READ_ERRORS as exc:
            reason = " ".join(str(exc).split())[:200]
            raise NpzProblem(f"array {key!r} is not readable ({type(exc).__name__}: {reason})") from None
    return arrays


def numeric(arrays: dict[str, np.ndarray], key: str, ndim: int, *, columns: int | None = None,
            finite: bool = True) -> np.ndarray:
    """``arrays[key]`` as float64 if it is a real numeric array of ``ndim`` dimensions (and ``columns``
    columns when given) with finite values; NpzProblem naming the array otherwise."""
    if key not in arrays:
        raise NpzProblem(f"missing array {key!r}")
    value = arrays[key]
    if value.dtype.kind not in NUMERIC_KINDS:
        raise NpzProblem(f"array {key!r} must hold real numbers, not {value.dtype} ({_kind(value.dtype)})")
    if value.ndim != ndim:
        want = "one value per row" if ndim == 1 else f"{ndim} dimensions"
        raise NpzProblem(f"array {key!r} has shape {value.shape}; expected {want}"
                         + (f" with {columns} columns" if columns else ""))
    if columns is not None and value.shape[-1] != columns:
        raise NpzProblem(f"array {key!r} has shape {value.shape}; expected {columns} columns")
    out = value.astype(np.float64)
    if finite and not np.all(np.isfinite(out)):
        raise NpzProblem(f"array {key!r} holds a value that is not a finite number")
    return out


def _kind(dtype: np.dtype) -> str:
    return {"c": "complex numbers", "U": "text", "S": "bytes", "O": "objects", "V": "raw records",
            "M": "dates", "m": "time spans"}.get(dtype.kind, "not numbers")
