"""Section 2.3.4.10: the version query (0x0E/0x09) names a device (设备 ID) and its reply names
the device whose version it carries. A reply naming another device answers another query (e.g.
another host's on a shared bus), never this one: not in the client, not in the log decoder."""
from __future__ import annotations

import pytest

from gimbal.client import GimbalClient
from gimbal.errors import GimbalTimeoutError, ReturnCodeError
from gimbal.log_decode import decode_frames
from gimbal.messages import decode_message, message_packet
from gimbal.messages.telemetry import VersionQuery, VersionReply
from gimbal.packet import encode_packet
from tests.gimbal.scripted_peer import ScriptedPeer, poll
from tests.gimbal.test_log_decode import frames_of

OTHER = VersionReply(0, 2, 0x0A0B0C0D)  # the remote controller's version (device ID 2)


def test_a_reply_about_another_device_arriving_first_is_stale(channel: str, peer: ScriptedPeer) -> None:
    """Before any SEQ echo the client pairs replies by command: the other device's reply, with its
    own SEQ, must not be taken for ours, which follows."""
    def reply_after_another(query: VersionQuery) -> VersionReply:
        peer.transport.send(encode_packet(message_packet(OTHER, 0x0500)))
        return VersionReply(0, query.device_id, 0x02050000)

    peer.answer(VersionQuery, reply_after_another, delay=0.05)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.5, retries=0) as gimbal:
        reply = gimbal.version(1)
        assert (reply.device_id, reply.version_text) == (1, "02.05.00.00")
        poll(lambda: gimbal.stats["stale_replies"] == 1)


@pytest.mark.parametrize("reply", [OTHER, VersionReply(2, 2)], ids=["ok", "nack"])
def test_a_reply_echoing_our_seq_but_naming_another_device_does_not_answer(
        channel: str, peer: ScriptedPeer, reply: VersionReply) -> None:
    peer.answer(VersionQuery, reply)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.1, retries=0) as gimbal:
        with pytest.raises(GimbalTimeoutError):
            gimbal.version(1)
        assert gimbal.stats["stale_replies"] == 1


@pytest.mark.parametrize("reply", [VersionReply(2), VersionReply(2, 0)], ids=["code-only", "device-0"])
def test_a_nack_that_names_no_device_still_answers(channel: str, peer: ScriptedPeer,
                                                   reply: VersionReply) -> None:
    """A NACK need not echo the rest (as for the focus replies); device ID 0 is reserved (2.3.3),
    so a NACK carrying it names no device."""
    peer.answer(VersionQuery, reply)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=0) as gimbal:
        with pytest.raises(ReturnCodeError):
            gimbal.version(1)


def test_an_ok_reply_must_name_the_device_asked_about() -> None:
    packet = message_packet(VersionReply(0, 0, 1), 1)
    with pytest.raises(ValueError, match="version_reply"):
        decode_message(packet, VersionQuery(1))
    assert decode_message(packet, VersionQuery).device_id == 0  # a class names no device


@pytest.mark.parametrize("legacy", [False, True], ids=["latest", "legacy"])
def test_the_log_decoder_pairs_a_version_reply_with_the_query_for_its_device(legacy: bool) -> None:
    """Another host's query for device 2 (SEQ 9) and ours for device 1 (SEQ 5); the replies come
    with a fixed SEQ, ours first: each goes to the query of the device it names."""
    frames = [*frames_of(VersionQuery(2), 9, 0x223, 1.0), *frames_of(VersionQuery(1), 5, 0x223, 1.001),
              *frames_of(VersionReply(0, 1, 0x02050000), 0x77, 0x222, 1.002, legacy),
              *frames_of(OTHER, 0x77, 0x222, 1.003, legacy)]
    replies = list(decode_frames(frames))[2:]
    assert [(r["fields"]["device_id"], r.get("request_seq")) for r in replies] == [(1, 5), (2, 9)]
