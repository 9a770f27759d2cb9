"""Finding the shipped robot configs: in the installed wheel (``gaitbot/_config``) or the source checkout's
``config/``, by path or by a robot's bare name."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from gaitbot.fields import FieldError

DEFAULT_ROBOT = "xl430-biped"


class ConfigError(FieldError):
    """A robot config is unusable. The message is one line: ``<file>: <field>: <what is wrong>``.

    Other modules that check a loaded config (the bus budget) build theirs with ``ConfigError(path,
    field, reason)`` so every config complaint looks the same.
    """


def shipped_config_dirs() -> list[Path]:
    """Directories holding the shipped robot files: the wheel's ``gaitbot/_config`` first (pyproject
    force-includes the top-level ``config/`` there), then ``<repo>/config`` for source checkouts."""
    dirs: list[Path] = []
    try:
        packaged = resources.files("gaitbot") / "_config"
        if isinstance(packaged, Path) and packaged.is_dir():
            dirs.append(packaged)
    except (ModuleNotFoundError, OSError):  # pragma: no cover - gaitbot is importable if we run
        pass
    checkout = Path(__file__).resolve().parents[2]
    # Only a source checkout (pyproject.toml beside gaitbot/): in an installed wheel parents[2] is
    # site-packages, where a "config" directory would belong to some other distribution.
    if (checkout / "pyproject.toml").is_file() and (checkout / "config").is_dir():
        dirs.append(checkout / "config")
    return dirs


def shipped_config_names() -> list[str]:
    """Names of the shipped robots (file stems), sorted."""
    return sorted({p.stem for d in shipped_config_dirs() for p in d.glob("*.toml")})


def resolve_config(name_or_path: str | Path) -> Path:
    """A config file from a path, or from the bare name of a shipped robot (``xl430-biped``).

    An existing file wins; otherwise a bare name (no directory part) is looked up among the shipped
    configs. Raises ConfigError listing the shipped names when neither exists.
    """
    path = Path(name_or_path)
    if path.is_file():
        return path
    text = str(name_or_path)
    if len(path.parts) == 1:
        stem = text[:-5] if text.endswith(".toml") else text
        for directory in shipped_config_dirs():
            candidate = directory / f"{stem}.toml"
            if candidate.is_file():
                return candidate
    shipped = ", ".join(shipped_config_names()) or "none found"
    raise ConfigError(text, "file", f"no such file, and not the name of a shipped robot (shipped: {shipped})")


def default_config_path() -> Path:
    """The built-in default robot's file (xl430-biped)."""
    return resolve_config(DEFAULT_ROBOT)
