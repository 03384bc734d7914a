"""The client's session (gimbal/session.py): its shared can.Notifier and its safety stop."""
from __future__ import annotations

import time
from pathlib import Path

import can
import pytest

from gimbal.client import GimbalClient
from gimbal.errors import BusError, GimbalTimeoutError, ReturnCodeError
from gimbal.messages import message_packet
from gimbal.messages.motion import SPEED_RELEASE, AnglesReply, GetAngles, SpeedControl, SpeedControlReply
from gimbal.messages.telemetry import ParameterPush
from gimbal.other_hosts import OtherHosts
from gimbal.packet import encode_packet
from gimbal.session import STOP_RETRY_S, _Taps
from gimbal.transport import CanTransport, HOST_RX_ID, HOST_TX_ID, packet_frames
from tests.gimbal.scripted_peer import RELEASE, ScriptedPeer, ZERO, speed_messages


# The client's can.Notifier is shared: any python-can listener sees the bus's traffic and ours.
def _drain(reader: can.BufferedReader) -> list[can.Message]:
    frames = []
    while (frame := reader.get_message(0.0)) is not None:
        frames.append(frame)
    return frames


def test_a_listener_added_later_gets_what_the_bus_saw_in_both_directions(channel: str,
                                                                           peer: ScriptedPeer) -> None:
    peer.answer(GetAngles, AnglesReply(0, 1, 10, 20, 30))
    reader = can.BufferedReader()
    with GimbalClient(interface="virtual", channel=channel) as client:
        client.add_listener(reader)
        client.get_angles()  # the taps come before the matcher: the whole reply is in the reader
    frames = _drain(reader)
    sent = [bytes(f.data) for f in frames if f.arbitration_id == HOST_TX_ID]
    received = [bytes(f.data) for f in frames if f.arbitration_id == HOST_RX_ID]
    assert all(not f.is_rx for f in frames if f.arbitration_id == HOST_TX_ID)
    assert all(f.is_rx for f in frames if f.arbitration_id == HOST_RX_ID)
    assert b"".join(sent) == encode_packet(peer.received[0].packet)
    assert b"".join(received) == encode_packet(message_packet(AnglesReply(0, 1, 10, 20, 30),
                                                              peer.received[0].packet.seq))


def test_a_bus_with_a_notifier_of_its_own_is_refused_in_one_line(channel: str) -> None:
    bus = can.Bus(interface="virtual", channel=channel)
    notifier = can.Notifier(bus, [])
    try:
        with pytest.raises(BusError, match="cannot receive on the CAN bus"):
            GimbalClient(bus)
    finally:
        notifier.stop()
        bus.shutdown()


def test_closing_lets_the_taps_finish_the_packet_in_progress_and_no_more(channel: str) -> None:
    bus = can.Bus(interface="virtual", channel=channel)
    reader = can.BufferedReader()
    taps = _Taps(CanTransport(bus), OtherHosts())
    taps.listeners.append(reader)
    push = packet_frames(encode_packet(message_packet(ParameterPush(0x01, 1, 2, 3), 7)), HOST_RX_ID)
    assert len(push) > 2
    try:
        taps.on_message_received(push[0])
        taps.close_at_packet_end()
        for frame in push[1:]:
            taps.on_message_received(frame)
        taps.on_message_received(push[0])  # the next packet: nobody reads it to its end
        taps.on_message_received(can.Message(arbitration_id=0x100, is_extended_id=False, data=b"\x01"))
    finally:
        bus.shutdown()
    assert [bytes(f.data) for f in _drain(reader)] == [bytes(f.data) for f in push]


def test_python_cans_own_logger_records_both_directions(channel: str, peer: ScriptedPeer, tmp_path: Path) -> None:
    """Any python-can log format works as a tap: here ``.asc``, whose lines say Tx or Rx."""
    peer.answer(GetAngles, AnglesReply(0, 1, 10, 20, 30))
    path = tmp_path / "session.asc"
    with GimbalClient(interface="virtual", channel=channel, listeners=[can.Logger(path)]) as client:
        client.get_angles()
    directions = {(m.arbitration_id, m.is_rx) for m in can.LogReader(path)}
    assert directions == {(HOST_TX_ID, False), (HOST_RX_ID, True)}


# The safety stop's two speed commands (zero in control, then zero with bit 7 clear: section
# 2.3.4.2, Figure 8) are counted apart in ``GimbalClient.stats``.
def test_the_zero_and_the_release_are_counted_each_once(channel: str, peer: ScriptedPeer) -> None:
    peer.answer(SpeedControl)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=0) as client:
        client.speed(10, 0)
    assert speed_messages(peer)[-2:] == [ZERO, RELEASE]
    assert (client.stats["stop_zero_sent"], client.stats["stop_release_sent"]) == (1, 1)


def test_a_stop_the_gimbal_leaves_unanswered_is_still_counted_as_sent(channel: str, peer: ScriptedPeer) -> None:
    """A gimbal gone silent: the two stops go out (each resent until its time is up, issue #26
    item 4) and are in the CAN log, so the counts say they were sent, not nothing."""
    peer.silence(SpeedControl)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.05, retries=0) as client:
        with pytest.raises(GimbalTimeoutError):
            client.speed(10, 0)
    stop = speed_messages(peer)[1:]  # after the speed command itself
    zeros = stop.index(RELEASE)
    assert stop[:zeros] == [ZERO] * zeros and stop[zeros:] == [RELEASE] * (len(stop) - zeros)
    assert zeros >= 2 and len(stop) - zeros >= 2
    assert (client.stats["stop_zero_sent"], client.stats["stop_release_sent"]) == (1, 1)
    assert client.stats["stop_resends"] == len(stop) - 2


def test_a_stop_the_gimbal_refuses_is_still_counted_as_sent(channel: str, peer: ScriptedPeer) -> None:
    peer.nack(SpeedControl, 0x02)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=0) as client:
        with pytest.raises(ReturnCodeError):
            client.speed(10, 0)
    assert speed_messages(peer)[-2:] == [ZERO, RELEASE]
    assert (client.stats["stop_zero_sent"], client.stats["stop_release_sent"]) == (1, 1)


def test_the_final_stop_is_resent_until_answered(channel: str, peer: ScriptedPeer) -> None:
    """Issue #26 item 4: under `sim --corrupt 0.1` a SIGTERM's zero and release went unanswered
    and were never sent again. Here the first two zeros and the first release get no reply."""
    unanswered = {ZERO: 2, RELEASE: 1}

    def flaky(request: SpeedControl) -> SpeedControlReply | None:
        key = (request.yaw_speed, request.roll_speed, request.pitch_speed, request.ctrl_byte)
        if unanswered.get(key, 0) > 0:
            unanswered[key] -= 1
            return None
        return SpeedControlReply()

    peer.answer(SpeedControl, flaky)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=0) as client:
        client.speed(10, 0)
        started = time.monotonic()
        client.stop_and_release()
        took = time.monotonic() - started
    assert speed_messages(peer)[1:] == [ZERO, ZERO, ZERO, RELEASE, RELEASE]
    assert client.stats["stop_resends"] == 3
    assert took < STOP_RETRY_S


def test_a_stop_whose_time_ran_out_before_it_was_sent_says_how_long_it_waited(channel: str,
                                                                           peer: ScriptedPeer) -> None:
    """A zero that overran its quarter second on a loaded machine left the release no time: its
    warning read "no reply within -2 ms"."""
    peer.silence(SpeedControl)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.05, retries=0) as client:
        release = SpeedControl(0, 0, 0, SPEED_RELEASE)
        with pytest.raises(GimbalTimeoutError, match=r"no reply within \d+ ms") as raised:
            client._stop_until_answered(release, until=time.monotonic() - 0.002)
    assert speed_messages(peer) == [RELEASE], raised.value  # sent once all the same
