"""What a failed exchange of an SDK bus says: the errors of gaitbot.bus.base built from an SDK result, the
attempts made and the servo's status error byte, in words a person can act on (docs/bus-faults.md).

A mixin of :class:`~gaitbot.bus.sdk_bus.SdkBus` (its port name, SDK, packet handler and vendor facts).
"""

from __future__ import annotations

from gaitbot.bus.base import BusError, CorruptReplies, PortError, ServoLate, ServoStatusError, ServoTimeout, miss_kind
from gaitbot.servos.status import describe_status_error, hardware_error_address

#: An attempt of a blocking exchange whose status packet came during the late-reply watch.
LATE_REPLY = "late"


class FaultReports:
    """The errors of an SDK bus, named and explained."""

    def _raise_on_port_failure(self, result: int, servo_id: int | None) -> None:
        if result in (self.sdk.COMM_TX_FAIL, self.sdk.COMM_PORT_BUSY, self.sdk.COMM_TX_ERROR):
            raise PortError(f"serial port {self.port_name} failed to send: {self._ph.getTxRxResult(result)}",
                            result_code=result, servo_id=servo_id)

    def _alert_register(self, servo_id: int, error: int) -> int | None:
        """The address of the register that says what an alert in ``error`` means (Dynamixel 2.0's Hardware
        Error Status), or None when the status byte says it all (vendor facts: ALERT_BITS)."""
        if not error & self.vendor.ALERT_BITS.get(self.protocol, 0):
            return None
        return hardware_error_address(self._model(servo_id).name)

    def _status_error(self, servo_id: int, error: int, budget_s: float | None = None) -> ServoStatusError:
        """ServoStatusError naming the fault; after an alert the hardware error register is read once to say
        what it means: blocking, or within ``budget_s`` (the read-back's frame) when given."""
        model = self._model(servo_id)
        hardware = None
        address = self._alert_register(servo_id, error)
        if address is not None:
            try:  # one attempt: the message is better with it, the stop does not depend on it
                if budget_s is None:
                    with self._transaction(servo_id):
                        self._drop_stale_input()
                        value, result, _ = self._ph.read1ByteTxRx(self.port, servo_id, address)
                    hardware = value if result == self.sdk.COMM_SUCCESS else None
                elif budget_s >= self.MIN_READ_BACK_BUDGET_S:
                    _outcome, frame = self._budgeted_read(servo_id, address, 1, budget_s, self.clock())
                    hardware = frame.params[0] if frame is not None else None
            except BusError:
                hardware = None
        fault = describe_status_error(self.family, self.protocol, error, hardware, model.name)
        detail = f"status error 0x{error:02X}" + (f", hardware error status 0x{hardware:02X}" if hardware else "")
        exc = ServoStatusError(f"servo {servo_id} on {self.port_name} reports {fault} ({detail})",
                               servo_id=servo_id, status_error=error, fault=fault)
        exc.detail_pending = hardware is None and address is not None  # read it once the robot is safe
        return exc

    def explain_status_error(self, exc: BusError) -> BusError:
        """The same fault with the Hardware Error Status read (blocking, one attempt) if the read-back had no
        time left for it in its frame: called by the session after the stop ramp, so the message says
        which hardware error the Alert bit meant."""
        if not (isinstance(exc, ServoStatusError) and getattr(exc, "detail_pending", False) and self._is_open):
            return exc
        try:
            return self._status_error(exc.servo_id, exc.status_error)
        except BusError:
            return exc

    def _no_answer(self, servo_id: int, results: list, what: str) -> ServoTimeout:
        attempts = len(results)
        result = results[-1]
        late = sum(r == LATE_REPLY for r in results)
        corrupt = sum(r == self.sdk.COMM_RX_CORRUPT for r in results)
        kind = miss_kind(late, corrupt, attempts - late - corrupt)
        if kind == "late":
            return self._late(servo_id, f"in {late} of {attempts} {what}")
        if kind == "damaged":
            some = "all" if corrupt == attempts else f"{corrupt} of"
            return CorruptReplies(
                f"servo {servo_id} on {self.port_name} sent a damaged status packet (bad checksum/CRC) in {some} "
                f"{attempts} {what}; check its cable, connectors and the bus wiring",
                result_code=result, servo_id=servo_id)
        others = [f"{n} {word}" for n, word in ((corrupt, "damaged"), (late, "late")) if n]
        how = f" (of the replies: {', '.join(others)})" if others else ""
        return ServoTimeout(
            f"servo {servo_id} on {self.port_name} did not return its present position after {attempts} {what}"
            f"{how}: no status packet within the reply timeout; check its power, cable, id and baud rate",
            result_code=result, servo_id=servo_id)

    def _unconfirmed(self, servo_id: int, address: int, data: bytes, result: int, late: int,
                     attempts: int) -> ServoTimeout:
        """A WRITE whose every attempt went unconfirmed (late: answered only during the late-reply watch)."""
        if late:
            return self._late(servo_id, f"to {late} of {attempts} writes to address {address}")
        shown = data[0] if len(data) == 1 else f"0x{data.hex()}"
        return ServoTimeout(f"servo {servo_id} on {self.port_name} did not confirm writing {shown} to "
                            f"address {address} ({self._ph.getTxRxResult(result)})",
                            result_code=result, servo_id=servo_id)

    def _late(self, servo_id: int, how: str = "") -> ServoLate:
        return ServoLate(f"servo {servo_id} on {self.port_name} answered late{' ' + how if how else ''}: its "
                         "status packet arrived after the reply timeout (about 34 ms at 1 Mbaud); check its Return "
                         "Delay Time and the adapter's latency timer", servo_id=servo_id)
