"""Output files: the one check every command runs on a path it will write, and the atomic write.

A command's output must never destroy what the user had: ``walk --trajectory w.csv --record w.csv`` would
overwrite the walk it is playing, ``eigen fit ex.npz -o ex.npz`` an example, ``calibrate -o
config/op3.toml`` the robot's config. So ``output_path`` refuses, in one line (exit 2), before any work:

- an output that is one of the command's inputs (the same file after resolving links);
- an output that is a robot config (a shipped one, or any TOML file with ``[bus]`` and ``[joints]``);
- an output that exists and is not a regular file (a FIFO would block the command forever, a device never
  takes a whole file), a folder, a missing or unwritable folder.

``write_output`` writes a whole file to a temporary file beside the target and renames it into place, so
a failure (a full disk, Ctrl-C, a bug) never leaves a half-written file where a good one was. Recordings
that are written while they happen (``walk --record``, ``record -o``) are checked the same way.
"""

from __future__ import annotations

import os
import stat
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path

from gaitbot.app.options import UsageError
from gaitbot.robot.config import resolve_config, shipped_config_dirs

#: The options through which commands read files: what an output may not be.
INPUT_OPTIONS = ("robot", "calibration", "terrain", "trajectory", "file", "files", "examples", "model", "commands",
                 "velocity", "recording", "description", "like", "map", "sim_model", "sim_map", "input")
#: A robot config is at most this big; a TOML file larger than this is not read to find out whether it is one.
_CONFIG_MAX_BYTES = 1_000_000


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.resolve() == b.resolve() or (a.exists() and b.exists() and os.path.samefile(a, b))
    except OSError:
        return False


def input_paths(args) -> list[Path]:
    """The files a command's arguments name as inputs (``--robot op3`` as its shipped file)."""
    found: list[Path] = []
    for name in INPUT_OPTIONS:
        value = getattr(args, name, None)
        for item in value if isinstance(value, (list, tuple)) else [value]:
            if not isinstance(item, (str, os.PathLike)) or not str(item).strip():
                continue
            path = Path(item)
            if name == "robot" and not path.is_file():
                try:
                    path = resolve_config(item)
                except Exception:  # noqa: BLE001 - an unknown robot is refused by its own check
                    continue
            found.append(path)
    return found


def _is_robot_config(path: Path) -> bool:
    """A shipped robot's file, or a TOML file holding ``[bus]`` and ``[joints]`` tables."""
    resolved = path.resolve()
    if any(resolved.parent == d.resolve() and resolved.suffix == ".toml" for d in shipped_config_dirs()):
        return True
    if path.suffix != ".toml" or not path.is_file() or path.stat().st_size > _CONFIG_MAX_BYTES:
        return False
    try:
        import tomllib
    except ImportError:  # pragma: no cover - Python 3.10
        import tomli as tomllib
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        return False
    return isinstance(data.get("bus"), dict) and isinstance(data.get("joints"), dict)


def output_path(value, flag: str = "-o", args=None, inputs: Iterable = ()) -> Path:
    """The checked output path named by ``flag``: refused (UsageError, exit 2) when it is empty, a folder, in a
    folder that is missing or unwritable, an existing file that is not a regular one, one of the inputs named
    in ``args`` (INPUT_OPTIONS) or ``inputs``, or a robot config."""
    if value is None or not str(value).strip():
        raise UsageError(f"{flag}: empty file name")
    out = Path(value)
    if out.is_dir():
        raise UsageError(f"{flag} {out}: is a directory")
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        raise UsageError(f"{flag} {out}: cannot write there (no such directory {parent})")
    try:
        mode = os.stat(out).st_mode if os.path.lexists(out) else None
    except OSError:
        mode = None  # a dangling link: a new file where it points
    if mode is not None and not stat.S_ISREG(mode):
        raise UsageError(f"{flag} {out}: not a regular file (a FIFO, a device or a socket); outputs are regular files "
                         f"or new paths")
    for source in [*(input_paths(args) if args is not None else []), *map(Path, inputs)]:
        if _same_file(out, source):
            raise UsageError(f"{flag} {out}: is one of this command's inputs ({source}); write to another file")
    if mode is not None and _is_robot_config(out):
        raise UsageError(f"{flag} {out}: is a robot config; write to another file")
    if not os.access(parent, os.W_OK) or (mode is not None and not os.access(out, os.W_OK)):
        raise UsageError(f"{flag} {out}: cannot write there (no permission)")
    return out


def write_output(out: Path, write: Callable[[Path], object], flag: str = "-o") -> None:
    """``write(path)`` into a temporary file beside ``out`` (same suffix: writers choose their format by it),
    then renamed onto ``out``; a failure to write is one line, exit 2, and leaves ``out`` as it was."""
    out = Path(out)
    folder = out.parent if str(out.parent) else Path(".")
    fd, name = tempfile.mkstemp(prefix=f".{out.stem}.", suffix=f".partial{out.suffix}", dir=folder)
    os.close(fd)
    temporary = Path(name)
    try:
        write(temporary)
        if out.exists():
            os.chmod(temporary, stat.S_IMODE(os.stat(out).st_mode))
        else:
            os.chmod(temporary, 0o666 & ~_umask())
        os.replace(temporary, out)
    except OSError as exc:
        raise UsageError(f"{flag} {out}: cannot write ({exc.strerror or exc})") from None
    finally:
        temporary.unlink(missing_ok=True)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
