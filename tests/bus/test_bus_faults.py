"""How a blocking exchange that failed every attempt names its servo (gaitbot.bus.bus_faults): by what most
of the attempts were, the rule the per-frame read-back keeps too (gaitbot.bus.base.miss_kind)."""

from __future__ import annotations

import dynamixel_sdk
import pytest

from gaitbot.bus.base import CorruptReplies, ServoLate, ServoTimeout, miss_kind
from gaitbot.bus.bus_faults import LATE_REPLY, FaultReports

CORRUPT, SILENT = dynamixel_sdk.COMM_RX_CORRUPT, dynamixel_sdk.COMM_RX_TIMEOUT


class Reports(FaultReports):
    port_name = "/dev/ttyTEST"
    sdk = dynamixel_sdk


@pytest.mark.parametrize("results, error, words", [
    ([CORRUPT] * 4, CorruptReplies, "damaged status packet (bad checksum/CRC) in all 4 reads"),
    ([CORRUPT, CORRUPT, LATE_REPLY, CORRUPT], CorruptReplies, "in 3 of 4 reads"),
    ([LATE_REPLY, SILENT, LATE_REPLY, CORRUPT], ServoLate, "answered late in 2 of 4 reads"),
    ([SILENT, SILENT, CORRUPT, SILENT], ServoTimeout, "after 4 reads (of the replies: 1 damaged)"),
    ([SILENT, LATE_REPLY, SILENT, CORRUPT], ServoTimeout, "(of the replies: 1 damaged, 1 late)"),
])
def test_a_servo_is_named_by_what_most_attempts_were(results, error, words):
    exc = Reports()._no_answer(5, results, "reads")
    assert type(exc) is error
    assert "servo 5 on /dev/ttyTEST" in str(exc) and words in str(exc), str(exc)
    assert exc.servo_id == 5


def test_ties_go_to_lateness_then_damage():
    assert miss_kind(late=2, damaged=2, silent=2) == "late"
    assert miss_kind(late=0, damaged=2, silent=2) == "damaged"
    assert miss_kind(late=1, damaged=0, silent=3) == "silent"
