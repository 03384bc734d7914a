"""python-can's udp_multicast loops every frame back to its sender marked as received: the CAN log
leaves out that echo of our own frame, once; a frame like it from another node, after the echo or
after a send that never went out, is logged as received. Closing the client stops the log (the
Notifier stops its listeners)."""
from __future__ import annotations

import uuid
from collections.abc import Iterator
from pathlib import Path

import can
import pytest

from gimbal.client import GimbalClient
from pipelines.outputs.can_log import CanLogWriter
from tests.gimbal.scripted_peer import poll
from tests.support import free_udp_port

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
