"""Each live input source, driven as the real thing is: keys written to a pty, datagrams over UDP, a recorded
evdev event stream; the watchdog and the refusals."""

import errno
import json
import os
import socket
import tty

import pytest

from gaitbot.errors import UserError
from gaitbot.gait.steer.command import STILL, TimedCommand, VelocityCommand
from gaitbot.inputs.keyboard import KeyboardSource, split_keys
from gaitbot.inputs.scripted import ScriptedSource
from gaitbot.inputs.open import open_source
from gaitbot.inputs.source import WATCHDOG_S
from gaitbot.inputs.udp import UdpSource

MAX = VelocityCommand(0.2, 0.1, 40.0)
MIN = VelocityCommand(-0.1, -0.1, -40.0)


@pytest.fixture
def pty_keyboard():
    master, slave = os.openpty()
    tty.setcbreak(slave)              # as KeyboardSource.on_terminal does with the real terminal
    source = KeyboardSource(slave, MAX, MIN)
    yield master, source
    os.close(master)
    os.close(slave)


def test_keys_on_a_pty_steer_an_arc_then_stop(pty_keyboard):
    master, keys = pty_keyboard
    assert keys.poll(0.0).command == STILL
    os.write(master, b"w")
    assert keys.poll(0.1).command == VelocityCommand(0.1, 0.0, 0.0)      # half of the most forward
    os.write(master, b"\x1b[D")                                           # left arrow: turn left as well
    assert keys.poll(0.2).command == VelocityCommand(0.1, 0.0, 20.0)
    os.write(master, b"+++")
    assert keys.poll(0.3).command.vx_m_s == pytest.approx(0.16)
    os.write(master, b"s")                                                # the opposite key: forward ends
    assert keys.poll(0.4).command == VelocityCommand(0.0, 0.0, pytest.approx(32.0))
    os.write(master, b"e ")                                               # sideways right, then space
    assert keys.poll(0.5).command == STILL


def test_backward_and_sideways_use_the_lower_limits(pty_keyboard):
    master, keys = pty_keyboard
    os.write(master, b"se")
    assert keys.poll(0.0).command == VelocityCommand(-0.05, -0.05, 0.0)


def test_an_escape_sequence_split_between_reads_is_kept():
    keys, tail = split_keys(b"w\x1b[")
    assert keys == ["w"] and tail == b"\x1b["
    keys, tail = split_keys(tail + b"Aq")
    assert keys == ["UP", "q"] and tail == b""


def test_udp_datagrams_hold_and_the_watchdog_stands_the_robot():
    udp = UdpSource.bind("127.0.0.1:0")
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sender.sendto(json.dumps({"vx": 0.05, "wz": 10}).encode(), udp.address)
        sender.sendto(json.dumps({"vx": 0.08}).encode(), udp.address)
        assert _poll_until(udp, 1.0).command == VelocityCommand(0.08, 0.0, 0.0)   # the newest wins
        assert udp.poll(1.0 + WATCHDOG_S * 0.9).command.vx_m_s == 0.08             # still within the watchdog
        late = udp.poll(1.0 + WATCHDOG_S * 1.1)
        assert late.command == STILL and "standing" in late.messages[0]
        sender.sendto(b"not json", udp.address)
        sender.sendto(b'{"fly": 1}', udp.address)
        bad = _poll_until(udp, 2.0, lambda r: r.messages)
        assert len(bad.messages) == 1 and "said once" in bad.messages[0]
        sender.sendto(b'{"stop": true}', udp.address)
        assert _poll_until(udp, 3.0, lambda r: r.end).end
    finally:
        sender.close()
        udp.close()


def _poll_until(source, now_s, done=lambda r: not r.command.is_still, tries=200):
    import time
    for _ in range(tries):
        reading = source.poll(now_s)
        if done(reading):
            return reading
        time.sleep(0.005)
    return reading


def test_a_flood_is_read_a_bounded_amount_per_frame():
    udp = UdpSource.bind("127.0.0.1:0")
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        for k in range(200):
            sender.sendto(json.dumps({"vx": k / 1000}).encode(), udp.address)
        first = udp.poll(0.0).command.vx_m_s
        assert first < 0.199          # at most 64 read in one frame
    finally:
        sender.close()
        udp.close()


def test_a_commands_file_plays_on_the_drive_clock():
    script = ScriptedSource([TimedCommand(0.5, VelocityCommand(0.1)), TimedCommand(2.0, stop=True)])
    assert script.poll(0.0).command == STILL and not script.poll(0.0).end
    assert script.poll(1.0).command == VelocityCommand(0.1)
    assert script.poll(2.0).end


class RecordedPad:
    """A gamepad's recorded event stream, read as evdev's InputDevice is: a batch per read, then nothing."""

    def __init__(self, batches):
        self.batches = list(batches)

    def read(self):
        if not self.batches:
            raise BlockingIOError(errno.EAGAIN, "no events")
        batch = self.batches.pop(0)
        if isinstance(batch, OSError):
            raise batch
        return iter(batch)

    def absinfo(self, code):
        from evdev import AbsInfo
        return AbsInfo(value=0, min=-32768, max=32767, fuzz=16, flat=128, resolution=0)


def test_a_recorded_gamepad_stream_needs_the_dead_man_and_stands_when_lost():
    evdev = pytest.importorskip("evdev")
    from gaitbot.inputs.gamepad import GamepadSource
    e = evdev.ecodes

    def ev(kind, code, value):
        return evdev.InputEvent(0, 0, kind, code, value)

    pad = RecordedPad([
        [ev(e.EV_ABS, e.ABS_Y, -32768), ev(e.EV_SYN, 0, 0)],                 # full forward, LB not held
        [ev(e.EV_KEY, e.BTN_TL, 1)],                                          # LB held
        [ev(e.EV_ABS, e.ABS_RX, 16384), ev(e.EV_ABS, e.ABS_X, 1000)],         # turn right; x within the dead zone
        OSError(errno.ENODEV, "No such device"),
    ])
    source = GamepadSource(pad, MAX, MIN)
    assert source.poll(0.0).command == STILL
    assert source.poll(0.1).command == VelocityCommand(0.1, 0.0, 0.0)
    turning = source.poll(0.2).command
    assert turning.vx_m_s == pytest.approx(0.1) and turning.vy_m_s == 0.0
    assert turning.wz_deg_s == pytest.approx(-0.5 * 40 * 16384.5 / 32767.5)
    lost = source.poll(0.3)
    assert lost.command == STILL and "lost" in lost.messages[0]


@pytest.mark.parametrize("spec", ["joystick", "udp:", "udp:99999", "udp:host:x", "commands:", "keyboard:x"])
def test_bad_input_specs_are_refused_in_one_line(spec):
    with pytest.raises(UserError, match="--input"):
        open_source(spec, MAX, MIN)
