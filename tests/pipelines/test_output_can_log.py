"""CAN log: both directions recorded by LoggingBus, flushed per frame, read back by can.LogReader."""
from __future__ import annotations

import uuid
from collections.abc import Callable
from pathlib import Path

import can
import pytest

from pipelines.outputs.can_log import CanLogWriter, LoggingBus


@pytest.fixture
def channel() -> str:
    return f"gimbaltrack-test-{uuid.uuid4().hex}"


def _message(arbitration_id: int, data: bytes) -> can.Message:
    return can.Message(arbitration_id=arbitration_id, data=data, is_extended_id=False)


def test_sent_and_received_frames_are_logged_with_their_direction(tmp_path: Path, channel: str) -> None:
    path = tmp_path / "can.log"
    peer = can.Bus(interface="virtual", channel=channel)
    bus = LoggingBus(can.Bus(interface="virtual", channel=channel), CanLogWriter(path))
    try:
        bus.send(_message(0x223, bytes([0xAA, 0x1A, 0x00])))
        assert peer.recv(5.0) is not None
        peer.send(_message(0x222, bytes([0xAA, 0x0E])))
        received = bus.recv(5.0)
        assert received is not None and received.arbitration_id == 0x222
        bus.send(_message(0x223, b"\x01\x02"))
    finally:
        bus.shutdown()
        peer.shutdown()
    logged = [(m.arbitration_id, bytes(m.data), m.is_rx) for m in can.LogReader(path)]
    assert logged == [(0x223, b"\xaa\x1a\x00", False), (0x222, b"\xaa\x0e", True), (0x223, b"\x01\x02", False)]
    stamps = [m.timestamp for m in can.LogReader(path)]
    assert stamps == sorted(stamps) and stamps[0] > 0


def test_proxy_filters_apply_after_logging(tmp_path: Path, channel: str) -> None:
    path = tmp_path / "can.log"
    peer = can.Bus(interface="virtual", channel=channel)
    bus = LoggingBus(can.Bus(interface="virtual", channel=channel), CanLogWriter(path),
                     can_filters=[{"can_id": 0x222, "can_mask": 0x7FF}])
    try:
        peer.send(_message(0x100, b"\x00"))
        peer.send(_message(0x222, b"\x01"))
        received = bus.recv(5.0)
        assert received is not None and received.arbitration_id == 0x222
    finally:
        bus.shutdown()
        peer.shutdown()
    assert [m.arbitration_id for m in can.LogReader(path)] == [0x100, 0x222]


def test_log_survives_a_crash(tmp_path: Path, run_and_crash: Callable[[str], None]) -> None:
    path = tmp_path / "can.log"
    run_and_crash(f"""
        import can
        from pipelines.outputs.can_log import CanLogWriter
        log = CanLogWriter({str(path)!r})
        for i in range(4):
            log.on_message_received(can.Message(arbitration_id=0x223, data=[i], is_extended_id=False,
                                                is_rx=bool(i % 2), timestamp=1.0 + i))
    """)
    assert [(bytes(m.data)[0], m.is_rx) for m in can.LogReader(path)] == [
        (0, False), (1, True), (2, False), (3, True)]


def test_writer_ignores_messages_after_stop(tmp_path: Path) -> None:
    path = tmp_path / "can.log"
    log = CanLogWriter(path, channel="can1")
    log.on_message_received(_message(0x222, b"\x01"))
    log.stop()
    log.stop()
    log.on_message_received(_message(0x222, b"\x02"))
    assert log.count == 1
    assert path.read_text().split()[1:] == ["can1", "222#01", "R"]


def test_a_bus_that_echoes_our_frames_logs_and_returns_each_frame_once(tmp_path):
    """python-can's udp_multicast hands a sender its own frames back; a virtual bus with
    receive_own_messages=True does the same, in-process."""
    channel = f"echo-{uuid.uuid4().hex}"
    path = tmp_path / "echo.log"
    echoing = can.Bus(interface="virtual", channel=channel, receive_own_messages=True)
    peer = can.Bus(interface="virtual", channel=channel)
    with LoggingBus(echoing, CanLogWriter(path)) as bus:
        for i in range(3):
            bus.send(can.Message(arbitration_id=0x223, is_extended_id=False, data=[i, 1, 2]))
        peer.send(can.Message(arbitration_id=0x222, is_extended_id=False, data=[9, 9]))
        received = bus.recv(0.5)
        assert received is not None and received.arbitration_id == 0x222
        assert bus.recv(0.05) is None  # the three echoes were swallowed
    peer.shutdown()
    logged = list(can.LogReader(path))
    assert [(m.arbitration_id, m.is_rx) for m in logged] == [(0x223, False)] * 3 + [(0x222, True)]


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_a_failed_write_never_stops_the_frames(tmp_path: Path, channel: str) -> None:
    """A full disk: the frames (a stop command among them) still go out whole; the log records why
    it stopped, for its owner to report."""
    path = tmp_path / "can.log"
    path.symlink_to("/dev/full")
    log = CanLogWriter(path)
    peer = can.Bus(interface="virtual", channel=channel)
    bus = LoggingBus(can.Bus(interface="virtual", channel=channel), log)
    try:
        for i in range(3):
            bus.send(_message(0x223, bytes([i])))
        assert [bytes(peer.recv(5.0).data) for _ in range(3)] == [b"\x00", b"\x01", b"\x02"]
    finally:
        bus.shutdown()
        peer.shutdown()
    assert log.error is not None and log.error.errno == 28 and log.count == 0
