"""LoggingBus drops an echo of its own frame once: a frame like it from another node, after the echo
or after a send that never went out, is received and logged as any other; shutting the proxy down
closes the log it owns."""
from __future__ import annotations

import uuid
from pathlib import Path

import can
import pytest

from pipelines.outputs.can_log import CanLogWriter, LoggingBus

FRAME = bytes([0xAA, 0x1A, 0x00])


def _frame() -> can.Message:
    return can.Message(arbitration_id=0x223, data=FRAME, is_extended_id=False)


def _logged(path: Path) -> list[tuple[int, bytes, bool]]:
    return [(m.arbitration_id, bytes(m.data), m.is_rx) for m in can.LogReader(path)]


def test_an_echo_is_matched_once_and_a_like_frame_from_another_node_is_received(tmp_path: Path) -> None:
    channel = f"echo-{uuid.uuid4().hex}"
    path = tmp_path / "can.log"
    echoing = can.Bus(interface="virtual", channel=channel, receive_own_messages=True)
    peer = can.Bus(interface="virtual", channel=channel)
    try:
        with LoggingBus(echoing, CanLogWriter(path)) as bus:
            bus.send(_frame())
            peer.send(_frame())  # the same id and data, from someone else
            received = bus.recv(2.0)
            assert received is not None and bytes(received.data) == FRAME
            assert bus.recv(0.05) is None
    finally:
        peer.shutdown()
    assert _logged(path) == [(0x223, FRAME, False), (0x223, FRAME, True)]


def test_a_send_the_bus_refused_leaves_no_echo_to_wait_for(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    channel = f"refuse-{uuid.uuid4().hex}"
    path = tmp_path / "can.log"
    inner = can.Bus(interface="virtual", channel=channel)
    peer = can.Bus(interface="virtual", channel=channel)

    def refuse(msg: can.Message, timeout: float | None = None) -> None:
        raise can.CanOperationError("transmit buffer full")

    try:
        with LoggingBus(inner, CanLogWriter(path)) as bus:
            monkeypatch.setattr(inner, "send", refuse)
            with pytest.raises(can.CanOperationError):
                bus.send(_frame())
            peer.send(_frame())
            received = bus.recv(2.0)
            assert received is not None and bytes(received.data) == FRAME
    finally:
        peer.shutdown()
    assert _logged(path) == [(0x223, FRAME, True)]


def test_shutting_the_proxy_down_closes_its_log(tmp_path: Path) -> None:
    path = tmp_path / "can.log"
    log = CanLogWriter(path)
    bus = LoggingBus(can.Bus(interface="virtual", channel=f"close-{uuid.uuid4().hex}"), log)
    bus.send(_frame())
    bus.shutdown()
    log.on_message_received(_frame())  # late: after the close
    assert log.count == 1 and _logged(path) == [(0x223, FRAME, False)]
