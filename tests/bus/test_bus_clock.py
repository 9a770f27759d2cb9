"""One clock: the SDK bus measures the read-back's budget on the clock it is given (the session's), not on
time.monotonic, so a session on a virtual clock and its bus agree on what is left of a frame (issue 21)."""

from __future__ import annotations

import pytest

from gaitbot.bus.dry_run import DryRunPort
from gaitbot.bus.factory import bus_class
from gaitbot.servos.models import servo_model

XL430 = servo_model("XL430-W250")


class SilentPort(DryRunPort):
    """Servo 1 never answers; every reply timeout the bus sets is noted (ms)."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.timeouts_ms: list[float] = []

    def setPacketTimeoutMillis(self, msec) -> None:  # noqa: N802
        self.timeouts_ms.append(float(msec))

    def _reply(self, servo_id: int, params: bytes) -> None:
        pass


def test_the_read_back_budget_runs_on_the_injected_clock():
    ticks = iter([100.0, 100.004, 100.004, 100.004])  # 4 ms pass between the start and the wait

    def clock() -> float:
        return next(ticks)

    port = SilentPort("dynamixel", 2.0, {1: XL430})
    bus = bus_class("dynamixel")("mock", 1_000_000, 2.0, {1: XL430}, port_handler=port, clock=clock)
    bus.open()
    result = bus.read_back(1, 0.010)
    assert result.outcome == "missed"
    assert port.timeouts_ms == [pytest.approx(6.0)]  # 10 ms budget less the 4 ms the clock says went by
    assert bus.late.abandoned[1] == [(4, 100.0)]  # the abandoned read is stamped on the same clock
