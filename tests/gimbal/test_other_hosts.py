"""Issue #26 item 3: another host's commands on our transmit id are seen at once; our own frames
(including udp_multicast's loopback of them) never are."""
from __future__ import annotations

import random

import can
import pytest

from gimbal.client import GimbalClient
from gimbal.messages import message_packet
from gimbal.messages.motion import AnglesReply, GetAngles, SpeedControl
from gimbal.other_hosts import OtherHosts
from gimbal.packet import encode_packet
from gimbal.transport import HOST_TX_ID, packet_frames
from tests.gimbal.scripted_peer import ScriptedPeer, poll


def frames_of(message: object, seq: int = 7, can_id: int = HOST_TX_ID) -> list[can.Message]:
    return packet_frames(encode_packet(message_packet(message, seq)), can_id)


def test_control_commands_and_queries_are_told_apart() -> None:
    watch = OtherHosts(clock=lambda: 5.0)
    for frame in frames_of(GetAngles()) + frames_of(SpeedControl(100, 0, 0)) * 2:
        watch.on_message_received(frame)
    for frame in frames_of(SpeedControl(100, 0, 0), can_id=0x222):  # the gimbal's id: not ours
        watch.on_message_received(frame)
    seen = watch.seen()
    assert (seen.commands, seen.control, seen.first_control) == (3, 2, 5.0)
    assert seen.describe() == "2 speed_control, 1 get_angles"
    assert watch.wait_for_control(0)


def test_queries_alone_are_no_controller() -> None:
    watch = OtherHosts()
    for frame in frames_of(GetAngles()):
        watch.on_message_received(frame)
    assert not watch.wait_for_control(0.01)
    assert watch.seen().control == 0


def test_two_clients_on_one_bus_see_each_other_and_never_themselves(channel: str, peer: ScriptedPeer) -> None:
    peer.answer(SpeedControl)
    peer.answer(GetAngles, AnglesReply(0, 1, 0, 0, 0))
    with GimbalClient(interface="virtual", channel=channel) as first, \
            GimbalClient(interface="virtual", channel=channel) as second:
        streamer = first.speed_streamer(max_age=60.0)
        streamer.set(5, 0)
        assert second.other_hosts.wait_for_control(2.0)
        assert "speed_control" in second.other_hosts.seen().describe()
        assert first.other_hosts.seen().commands == 0
        second.get_angles()
        poll(lambda: first.other_hosts.seen().names.get("get_angles") == 1)
        assert first.other_hosts.seen().control == 0


def test_udp_multicast_loopback_of_our_own_frames_is_not_another_host() -> None:
    tx_id = random.randrange(0x300, 0x700)  # ids of its own: other runs share the multicast port
    try:
        bus = can.Bus(interface="udp_multicast", channel="239.74.163.9")
    except (OSError, can.CanError) as exc:
        pytest.skip(f"udp_multicast unavailable: {exc}")
    with GimbalClient(bus, tx_id=tx_id, rx_id=tx_id + 1, timeout=0.02, retries=0) as client:
        streamer = client.speed_streamer(max_age=60.0)
        streamer.set(5, 0)
        poll(lambda: streamer.stats["sent"] >= 10)
        assert client.other_hosts.seen().commands == 0
    bus.shutdown()
