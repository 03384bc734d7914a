"""Focus motor replies (0x0E/0x12, section 2.3.4.19) share one CmdSet/CmdID between two layouts;
the reply's sub-ID tells them apart. Figure 33 and Figure 34 both say of the reply's sub-ID:
"命令子 ID ... 与命令帧数据一致" (command sub-ID ... the same as in the command frame). A reply
of the other sub-command must never be read as the answer to a command."""
from __future__ import annotations

import struct
from collections.abc import Iterator

import pytest

from gimbal.client import GimbalClient
from gimbal.errors import PayloadError, ReturnCodeError
from gimbal.messages import decode_message
from gimbal.messages.external import (FocusCalibration, FocusPositionQuery,
                                      FocusPositionReply)
from gimbal.packet import Packet
from tests.gimbal.scripted_peer import ScriptedPeer

POSITION_REPLY = struct.pack("<BBBBI", 0, 0x15, 0x00, 0x03, 4000)  # Figure 34, sub-ID 0x15
CALIBRATION_REPLY = bytes((0, 0x02, 0x00, 0x01))  # Figure 33, sub-ID 0x02, result 1 (failed)


@pytest.mark.parametrize("legacy", [False, True], ids=["latest", "legacy"])
@pytest.mark.parametrize("request_msg,payload", [(FocusCalibration(), POSITION_REPLY),
                                                 (FocusPositionQuery(), CALIBRATION_REPLY)],
                         ids=["calibration<-position", "position<-calibration"])
def test_a_reply_of_the_other_sub_command_is_refused(request_msg: object, payload: bytes,
                                                     legacy: bool) -> None:
    """Read as the answer to the other sub-command, the position reply's calibration state 3
    became a calibration ``result`` 3, and the calibration reply's result 1 became 'not
    calibrated' with no position."""
    packet = Packet.reply(0x0E, 0x12, payload, seq=1, legacy=legacy)
    with pytest.raises(PayloadError, match="sub-ID"):
        decode_message(packet, request_msg)  # type: ignore[arg-type]


@pytest.fixture
def client(channel: str, peer: ScriptedPeer) -> Iterator[GimbalClient]:
    with GimbalClient(interface="virtual", channel=channel, timeout=0.5, retries=0) as gimbal:
        yield gimbal


def test_a_gimbal_that_does_not_echo_seq_pairs_focus_replies_by_sub_id(
        client: GimbalClient, peer: ScriptedPeer) -> None:
    """Replies paired by CmdSet/CmdID (no SEQ echo): a calibration reply arriving while a
    position query waits is not its answer; the position reply that follows is."""
    peer.answer(FocusPositionQuery, FocusPositionReply(0, 0x15, 0x00, 0x03, 4000), seq=0x0001, delay=0.1)
    waiter = client.submit(FocusPositionQuery())
    peer.transport.send(Packet.reply(0x0E, 0x12, CALIBRATION_REPLY, seq=0x0002))
    assert waiter.wait(2.0)
    reply = client.result(waiter)
    assert isinstance(reply, FocusPositionReply)
    assert (reply.calibration_state, reply.position) == (0x03, 4000)
    assert client.stats["stale_replies"] == 1


NACK_WITHOUT_SUB_ID = bytes((0x01, 0x00, 0x00, 0x00))  # return code 0x01, the other fields zero


@pytest.mark.parametrize("legacy", [False, True], ids=["latest", "legacy"])
def test_a_nack_answers_its_command_whatever_follows_its_return_code(legacy: bool) -> None:
    """An error reply need not echo the sub-command: its return code is the answer (it was
    refused as 'another sub-command's reply', and the client then waited for a reply it had)."""
    packet = Packet.reply(0x0E, 0x12, NACK_WITHOUT_SUB_ID, seq=1, legacy=legacy)
    assert decode_message(packet, FocusCalibration()).return_code == 0x01


def test_the_client_reports_a_focus_nack_that_does_not_echo_the_sub_id(
        client: GimbalClient, peer: ScriptedPeer) -> None:
    waiter = client.submit(FocusCalibration())
    peer.transport.send(Packet.reply(0x0E, 0x12, NACK_WITHOUT_SUB_ID, seq=waiter.seq))
    assert waiter.wait(2.0)
    with pytest.raises(ReturnCodeError):
        client.result(waiter)
