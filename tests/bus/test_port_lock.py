"""The SDK's port lock after a signal lands mid-transaction (issue 26 item 2).

Both SDKs take a lock (``port.is_using``) when a packet goes out and give it back when its reply has
been read; a KeyboardInterrupt (Ctrl-C) or Terminated (SIGTERM) raised between the two used to leave it
taken, and every later packet -- the stop ramp's included -- was refused as "Port is in use!". Here the
interrupt is raised from inside the port itself, at each place of each kind of transaction, and the
next goal write (the stop ramp's first packet) must still reach the wire.
"""

from __future__ import annotations

import pytest

from gaitbot.bus.factory import bus_class
from gaitbot.bus.dry_run import DryRunPort
from gaitbot.servos import wire
from gaitbot.servos.models import servo_model

XL430 = servo_model("XL430-W250")
AX12 = servo_model("AX-12A")
STS = servo_model("STS3215")


class InterruptingPort(DryRunPort):
    """Raises KeyboardInterrupt once, from ``writePort`` (before the bytes leave) or from ``readPort``
    (while the reply is being read), during the next transaction whose instruction is ``instruction``."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.instruction: int | None = None
        self.where = "write"
        self._armed_read = False

    def writePort(self, packet) -> int:  # noqa: N802
        data = bytes(packet)
        if self.instruction is not None:
            frame = wire.parse(data, self.framing, status=False)
            if frame.checksum_ok and frame.instruction == self.instruction:
                self.instruction = None
                if self.where == "write":
                    raise KeyboardInterrupt
                self._armed_read = True
        return super().writePort(packet)

    def readPort(self, length: int) -> bytes:  # noqa: N802
        if self._armed_read:
            self._armed_read = False
            raise KeyboardInterrupt
        return super().readPort(length)


def _bus(backend: str, protocol: float, model, ids=(1, 2)):
    port = InterruptingPort(backend, protocol, {i: model for i in ids})
    bus = bus_class(backend)("mock", 1_000_000, protocol, {i: model for i in ids}, port_handler=port, retries=0)
    bus.open()
    return bus, port


def _goal_writes(port: DryRunPort) -> int:
    return sum(wire.parse(p, port.framing, status=False).instruction == wire.INST_SYNC_WRITE
               for p in port.tx_packets)


TRANSACTIONS = {
    "read_back": (wire.INST_READ, lambda bus: bus.read_back(1, 0.01)),
    "ping": (wire.INST_PING, lambda bus: bus.ping(1)),
    "read_health": (wire.INST_READ, lambda bus: bus.read_health(1)),
    "set_torque": (wire.INST_WRITE, lambda bus: bus.set_torque([1, 2], True)),
    "goal_write": (wire.INST_SYNC_WRITE, lambda bus: bus.write_goal_ticks({1: 500, 2: 500})),
}


@pytest.mark.parametrize("backend,protocol,model", [("dynamixel", 2.0, XL430), ("dynamixel", 1.0, AX12),
                                                    ("feetech", 1.0, STS)])
@pytest.mark.parametrize("where", ["write", "read"])
@pytest.mark.parametrize("transaction", sorted(TRANSACTIONS))
def test_the_next_goal_goes_out_after_an_interrupt_inside_a_transaction(backend, protocol, model, where,
                                                                        transaction):
    instruction, call = TRANSACTIONS[transaction]
    if where == "read" and instruction == wire.INST_SYNC_WRITE:
        pytest.skip("a goal sync write has no reply to read")
    bus, port = _bus(backend, protocol, model)
    port.instruction, port.where = instruction, where
    with pytest.raises(KeyboardInterrupt):
        call(bus)
    assert port.instruction is None, "the interrupt was not raised: the test did not test anything"
    assert not port.is_using, "the SDK's port lock stayed taken after the interrupt"
    before = _goal_writes(port)
    bus.write_goal_ticks({1: 510, 2: 510})  # the stop ramp's first packet (inside every model's range)
    assert _goal_writes(port) == before + 1
    assert port.present_ticks(1) == 510
