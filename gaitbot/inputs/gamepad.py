"""A gamepad through the Linux input devices (evdev): hold LB to walk, left stick to go, right stick to turn.

Mapping (the xpad/Xbox layout; most USB and Bluetooth pads follow it under Linux):
- left stick up/down (ABS_Y): forward/backward; left stick left/right (ABS_X): sideways;
- right stick left/right (ABS_RX): turn;
- LB held (BTN_TL): the dead-man button; released, the robot stands (nothing moves by accident);
- START (BTN_START): stop and end the drive;
- D-pad up/down (ABS_HAT0Y): speed level up/down in tenths of the robot's limits (start 50%).
A stick within 10% of its centre counts as centred. evdev sends events only when something changes, so a
pad held still is silent; the watchdog here is the device itself: unplugged or out of range (its read
fails), the robot stands and the loss is said once.
"""

from __future__ import annotations

from gaitbot.gait.steer.command import STILL, VelocityCommand
from gaitbot.inputs.source import InputError, Reading

DEADZONE = 0.10
AXES = {"ABS_Y": ("vx_m_s", -1), "ABS_X": ("vy_m_s", -1), "ABS_RX": ("wz_deg_s", -1)}  # stick up is negative


def _codes():
    from evdev import ecodes
    return ecodes


class GamepadSource:
    """Stick positions and buttons from an evdev device (or any object with ``read()`` and ``absinfo(code)``)."""

    name = "gamepad"

    def __init__(self, device, max_command: VelocityCommand, min_command: VelocityCommand) -> None:
        self.device = device
        self.max_command = max_command
        self.min_command = min_command
        self.level = 0.5
        self.sticks = {axis: 0.0 for axis, _ in AXES.values()}
        self.enabled = False
        self.lost = False
        ecodes = _codes()
        self._axis_of_code = {getattr(ecodes, name): spec for name, spec in AXES.items()}
        self._ecodes = ecodes

    @classmethod
    def open(cls, path: str | None, max_command: VelocityCommand, min_command: VelocityCommand) -> "GamepadSource":
        try:
            import evdev
        except ImportError:
            raise InputError("--input gamepad needs evdev: pip install 'gaitbot[drive]'") from None
        paths = [path] if path else evdev.list_devices()
        for candidate in paths:
            try:
                device = evdev.InputDevice(candidate)
            except OSError as exc:
                if path:
                    raise InputError(f"--input gamepad:{path}: cannot open: {exc.strerror or exc}") from None
                continue
            keys = device.capabilities().get(evdev.ecodes.EV_KEY, [])
            if evdev.ecodes.BTN_TL in keys or path:
                return cls(device, max_command, min_command)
            device.close()
        raise InputError("--input gamepad: no gamepad found under /dev/input (name one: gamepad:/dev/input/eventN)")

    def _normalised(self, code: int, value: int) -> float:
        info = self.device.absinfo(code)
        centre = (info.max + info.min) / 2.0
        half = (info.max - info.min) / 2.0 or 1.0
        x = max(-1.0, min(1.0, (value - centre) / half))
        return 0.0 if abs(x) < DEADZONE else x

    def _handle(self, event) -> bool:
        """Apply one event; True when it asks to end the drive."""
        e = self._ecodes
        if event.type == e.EV_ABS and event.code in self._axis_of_code:
            axis, sign = self._axis_of_code[event.code]
            self.sticks[axis] = sign * self._normalised(event.code, event.value)
        elif event.type == e.EV_ABS and event.code == e.ABS_HAT0Y and event.value:
            self.level = min(1.0, max(0.1, round(self.level - 0.1 * event.value, 1)))  # hat up is -1
        elif event.type == e.EV_KEY and event.code == e.BTN_TL:
            self.enabled = bool(event.value)
        elif event.type == e.EV_KEY and event.code == e.BTN_START and event.value:
            return True
        return False

    def command(self) -> VelocityCommand:
        if not self.enabled or self.lost:
            return STILL
        values = {}
        for axis, x in self.sticks.items():
            limit = getattr(self.max_command if x > 0 else self.min_command, axis)
            values[axis] = self.level * abs(x) * limit if x else 0.0
        return VelocityCommand(**values)

    def poll(self, now_s: float) -> Reading:
        reading = Reading()
        if not self.lost:
            try:
                for event in self.device.read():
                    reading.end |= self._handle(event)
            except BlockingIOError:
                pass
            except OSError as exc:
                self.lost = True
                reading.messages.append(f"gamepad: lost ({exc.strerror or exc}): standing")
        reading.command = STILL if reading.end else self.command()
        return reading

    def close(self) -> None:
        close = getattr(self.device, "close", None)
        if close is not None:
            close()
