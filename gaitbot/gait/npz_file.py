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


class NpzProblem(ValueError):
    """One line: what is wrong with which array of the file."""


def read_npz(path: str | Path) -> dict[str, np.ndarray]:
    """Every array of the file, each checked for its size and kind before its data is read.

    Raises OSError (the file cannot be read: missing, a directory, a device) or NpzProblem."""
    import io

    data = read_user_file(path)
    try:
        archive = zipfile.ZipFile(io.BytesIO(data))
        names = archive.namelist()
    except (zipfile.BadZipFile, zipfile.LargeZipFile, ValueError, EOFError, OSError) as exc:
        raise NpzProblem(f"not a readable .npz (not a zip archive: {exc})") from None
    arrays: dict[str, np.ndarray] = {}
    for member in names:
        key = member[:-4] if member.endswith(".npy") else member
        try:
            with archive.open(member) as f:
                version = np.lib.format.read_magic(f)
                if version == (1, 0):
                    shape, _fortran, dtype = np.lib.format.read_array_header_1_0(f)
                else:
                    shape, _fortran, dtype = np.lib.format.read_array_header_2_0(f)
                if dtype.hasobject:
                    raise NpzProblem(f"array {key!r} holds Python objects (pickles are not read)")
                count = int(np.prod(shape, dtype=object)) if shape else 1
                if count > MAX_ELEMENTS:
                    raise NpzProblem(f"array {key!r} claims {count} elements, more than the {MAX_ELEMENTS} "
                                     "such a file may hold")
            with archive.open(member) as f:
                arrays[key] = np.lib.format.read_array(f, allow_pickle=False)
        except NpzProblem:
            raise
        except (ValueError, EOFError, OSError, zipfile.BadZipFile, zipfile.LargeZipFile, TypeError,
                OverflowError, MemoryError, UnicodeDecodeError, SyntaxError, RuntimeError) as exc:
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
