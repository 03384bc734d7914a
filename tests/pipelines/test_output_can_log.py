"""CAN log: both directions recorded by a CanLogWriter on the client's Notifier (received) and at
send (ours), flushed per frame, read back by can.LogReader."""
from __future__ import annotations

import time
import uuid
from collections.abc import Callable, Iterator
from pathlib import Path

import can
import pytest

from gimbal.client import GimbalClient
from pipelines.outputs.can_log import CanLogWriter
from tests.gimbal.scripted_peer import poll
from tests.support import free_udp_port


@pytest.fixture
def channel() -> str:
    return f"gimbaltrack-test-{uuid.uuid4().hex}"


def _message(arbitration_id: int, data: bytes) -> can.Message:
    return can.Message(arbitration_id=arbitration_id, data=data, is_extended_id=False)


def test_sent_and_received_frames_are_logged_with_their_direction(tmp_path: Path, channel: str) -> None:
    path = tmp_path / "can.log"
    peer = can.Bus(interface="virtual", channel=channel)
    bus = can.Bus(interface="virtual", channel=channel)
    try:
        with GimbalClient(bus, listeners=[CanLogWriter(path)]) as client:
            client.transport.send(bytes([0xAA, 0x1A, 0x00]))
            assert peer.recv(5.0) is not None
            peer.send(_message(0x222, bytes([0xAA, 0x0E])))
            poll(lambda: len(list(can.LogReader(path))) == 2)
            client.transport.send(b"\x01\x02")
    finally:
        bus.shutdown()
        peer.shutdown()
    logged = [(m.arbitration_id, bytes(m.data), m.is_rx) for m in can.LogReader(path)]
    assert logged == [(0x223, b"\xaa\x1a\x00", False), (0x222, b"\xaa\x0e", True), (0x223, b"\x01\x02", False)]
    stamps = [m.timestamp for m in can.LogReader(path)]
    assert stamps == sorted(stamps) and stamps[0] > 0


def test_the_log_holds_all_traffic_read_not_only_the_gimbals(tmp_path: Path, channel: str) -> None:
    path = tmp_path / "can.log"
    peer = can.Bus(interface="virtual", channel=channel)
    bus = can.Bus(interface="virtual", channel=channel)
    try:
        with GimbalClient(bus, listeners=[CanLogWriter(path)]):
            peer.send(_message(0x100, b"\x00"))
            peer.send(_message(0x222, b"\x01"))
            poll(lambda: len(list(can.LogReader(path))) == 2)
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


def test_a_bus_that_returns_our_frames_logs_each_frame_once(tmp_path: Path) -> None:
    """A bus opened with receive_own_messages=True hands our frames back marked is_rx=False
    (python-can's convention): those are what the log holds, not a second copy made at send."""
    channel = f"echo-{uuid.uuid4().hex}"
    path = tmp_path / "echo.log"
    echoing = can.Bus(interface="virtual", channel=channel, receive_own_messages=True)
    peer = can.Bus(interface="virtual", channel=channel)
    with GimbalClient(echoing, listeners=[CanLogWriter(path)]) as client:
        for i in range(3):
            client.transport.send(bytes([i, 1, 2]))
        peer.send(can.Message(arbitration_id=0x222, is_extended_id=False, data=[9, 9]))
        poll(lambda: len(list(can.LogReader(path))) == 4)
        time.sleep(0.05)  # nothing more comes
    echoing.shutdown()
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
    bus = can.Bus(interface="virtual", channel=channel)
    try:
        with GimbalClient(bus, listeners=[log]) as client:
            for i in range(3):
                client.transport.send(bytes([i]))
            assert [bytes(peer.recv(5.0).data) for _ in range(3)] == [b"\x00", b"\x01", b"\x02"]
    finally:
        bus.shutdown()
        peer.shutdown()
    assert log.error is not None and log.error.errno == 28 and log.count == 0


# python-can's udp_multicast loops every frame back to its sender marked as received: the CAN log
# leaves out that echo of our own frame, once; a frame like it from another node, after the echo or
# after a send that never went out, is logged as received. Closing the client stops the log (the
# Notifier stops its listeners).
FRAME = bytes([0xAA, 0x1A, 0x00])
GROUP = "239.74.163.9"


def _frame() -> can.Message:
    return can.Message(arbitration_id=0x223, data=FRAME, is_extended_id=False)


def _logged(path: Path) -> list[tuple[int, bytes, bool]]:
    return [(m.arbitration_id, bytes(m.data), m.is_rx) for m in can.LogReader(path)]


@pytest.fixture
def multicast() -> Iterator[tuple[can.BusABC, can.BusABC]]:
    """Two udp_multicast buses on a private port: ours and another node's."""
    port = free_udp_port()
    ours = can.Bus(interface="udp_multicast", channel=GROUP, port=port)
    other = can.Bus(interface="udp_multicast", channel=GROUP, port=port)
    yield ours, other
    ours.shutdown()
    other.shutdown()


def test_an_echo_is_left_out_once_and_a_like_frame_from_another_node_is_logged(
        tmp_path: Path, multicast: tuple[can.BusABC, can.BusABC]) -> None:
    ours, other = multicast
    path = tmp_path / "can.log"
    with GimbalClient(ours, listeners=[CanLogWriter(path)]) as client:
        client.transport.send(FRAME)
        assert other.recv(2.0) is not None
        other.send(_frame())  # the same id and data, from someone else
        poll(lambda: len(_logged(path)) == 2)
        peer_echo = other.recv(2.0)  # the other node hears its own frame too; ours must not log it twice
        assert peer_echo is not None
    assert _logged(path) == [(0x223, FRAME, False), (0x223, FRAME, True)]


def test_a_send_the_bus_refused_leaves_no_echo_to_wait_for(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                           multicast: tuple[can.BusABC, can.BusABC]) -> None:
    ours, other = multicast
    path = tmp_path / "can.log"

    def refuse(msg: can.Message, timeout: float | None = None) -> None:
        raise can.CanOperationError("transmit buffer full")

    with GimbalClient(ours, listeners=[CanLogWriter(path)]) as client:
        monkeypatch.setattr(ours, "send", refuse)
        with pytest.raises(can.CanOperationError):
            client.transport.send(FRAME)
        other.send(_frame())
        poll(lambda: len(_logged(path)) == 1)
    assert _logged(path) == [(0x223, FRAME, True)]


def test_closing_the_client_closes_its_log(tmp_path: Path) -> None:
    path = tmp_path / "can.log"
    log = CanLogWriter(path)
    bus = can.Bus(interface="virtual", channel=f"close-{uuid.uuid4().hex}")
    with GimbalClient(bus, listeners=[log]) as client:
        client.transport.send(FRAME)
    log.on_message_received(_frame())  # late: after the close
    bus.shutdown()
    assert log.count == 1 and _logged(path) == [(0x223, FRAME, False)]
