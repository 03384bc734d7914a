"""``CanTransport.recv(timeout)`` keeps its deadline on a busy bus: DJI's accessory traffic on
other ids (0x530/0x531/0x426, thousands of frames a second, FIELD_NOTES.md "Transport") never
yields a packet, and must not keep the caller waiting past its timeout."""
from __future__ import annotations

import time

import can

from gimbal.transport import CanTransport

TIMEOUT_S = 0.05
FLOOD_S = 3.0  # the fake bus falls silent after this long, so a transport that ignores its deadline returns late


class FloodedBus(can.BusABC):
    """A bus with an endless stream of accessory frames on 0x530 (for ``FLOOD_S`` seconds)."""

    def __init__(self) -> None:
        super().__init__(channel="flooded")
        self._until = time.monotonic() + FLOOD_S

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        """Nothing listens."""

    def _recv_internal(self, timeout: float | None) -> tuple[can.Message | None, bool]:
        if time.monotonic() >= self._until:
            return None, False
        time.sleep(0.0005)
        return can.Message(arbitration_id=0x530, is_extended_id=False, data=b"\x55\x0d\x04\x33"), False


def test_recv_returns_none_at_its_deadline_while_foreign_frames_keep_coming() -> None:
    bus = FloodedBus()
    try:
        transport = CanTransport(bus)
        start = time.monotonic()
        assert transport.recv(TIMEOUT_S) is None
        assert time.monotonic() - start < TIMEOUT_S + 1.0  # a loaded machine may stall; ignoring the deadline costs 3 s
        assert transport.foreign_frames > 0
    finally:
        bus.shutdown()
