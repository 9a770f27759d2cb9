"""The emulated servos kept across a restart: each servo's model and EEPROM (id, baud rate, limits ...) in a
JSON file, as a real servo keeps them over a power cycle. ``--state FILE`` on the emulator's command line:
``gaitbot setup`` on factory-fresh servos plugged one at a time, Ctrl-C, and the next run of the emulator
with the same file is the same servos, all connected, at the ids and rate setup gave them.

Written after every EEPROM write a servo keeps (so an emulator killed at any moment leaves what its servos
would hold), by writing a new file and renaming it over the old one (never half a file). Format::

    {"format": "gaitbot-emulator-state", "version": 1, "backend": "dynamixel", "protocol": 2.0,
     "servos": [{"model": "XL430-W250", "eeprom": "<hex bytes of the EEPROM area>"}, ...]}
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from gaitbot.servos.models import SERVO_MODELS, ServoModel

FORMAT, VERSION = "gaitbot-emulator-state", 1


def write_state(path: str | Path, backend: str, protocol: float, servos: list[tuple[ServoModel, bytes]]) -> None:
    """Save the servos (model, EEPROM bytes, in chain order) to ``path`` at once (a rename over the old file)."""
    path = Path(path)
    data = {"format": FORMAT, "version": VERSION, "backend": backend, "protocol": float(protocol),
            "servos": [{"model": model.name, "eeprom": bytes(eeprom).hex()} for model, eeprom in servos]}
    partial = path.with_name(path.name + ".partial")
    partial.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    os.replace(partial, path)


def read_state(path: str | Path, backend: str, protocol: float) -> list[tuple[ServoModel, bytes]]:
    """The servos saved in ``path`` (model, EEPROM bytes); ValueError (one line naming the file) for a file
    that is not a state file, or one of a bus of another backend or protocol."""
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"--state {path}: not readable as an emulator state file ({exc})") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT or data.get("version") != VERSION:
        raise ValueError(f"--state {path}: not an emulator state file (format {FORMAT!r}, version {VERSION})")
    if (data.get("backend"), data.get("protocol")) != (backend, float(protocol)):
        raise ValueError(f"--state {path}: holds {data.get('backend')} protocol {data.get('protocol')} servos, "
                         f"the chain asked for is {backend} protocol {float(protocol)}")
    servos = []
    entries = data.get("servos")
    if not isinstance(entries, list) or not entries:
        raise ValueError(f"--state {path}: servos: a list of at least one servo is needed")
    for k, entry in enumerate(entries):
        model = SERVO_MODELS.get(entry.get("model")) if isinstance(entry, dict) else None
        try:
            eeprom = bytes.fromhex(entry["eeprom"]) if model is not None else b""
        except (KeyError, TypeError, ValueError):
            eeprom = b""
        if model is None or not eeprom:
            raise ValueError(f"--state {path}: servos[{k}]: needs a known model and its EEPROM bytes in hex")
        servos.append((model, eeprom))
    return servos
