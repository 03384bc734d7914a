"""The reply matcher alone, with no bus: fed frames as a can.Notifier would feed them."""
from __future__ import annotations

import itertools
import logging

import can
import pytest

from gimbal.client import GimbalClient
from gimbal.errors import GimbalTimeoutError
from gimbal.matcher import ECHO_EVIDENCE, FIRST_SEQ, GIVEN_UP_KEPT, PendingReply, ReplyMatcher
from gimbal.messages import Message, message_packet
from gimbal.messages.motion import AnglesReply, GetAngles, SpeedControl, SpeedControlReply
from gimbal.messages.telemetry import ParameterPush, VersionQuery, VersionReply
from gimbal.packet import Packet, REPLY_CMD_TYPE, encode_packet
from gimbal.transport import HOST_RX_ID, HOST_TX_ID, packet_frames
from gimbal.watchdog import DISENGAGED, ENGAGED
from tests.gimbal.scripted_peer import ScriptedPeer, poll


def _feed(matcher: ReplyMatcher, packet: Packet, arbitration_id: int = HOST_RX_ID) -> None:
    for frame in packet_frames(encode_packet(packet), arbitration_id):
        matcher.on_message_received(frame)


def _reply(message: Message, seq: int, *, legacy: bool = False) -> Packet:
    return message_packet(message, seq, legacy=legacy)


def _submit(matcher: ReplyMatcher, message: Message) -> PendingReply:
    seq, raw = matcher.encode(message)
    waiter = PendingReply(message, seq, raw)
    matcher.expect(waiter)
    return waiter


@pytest.fixture
def matcher() -> ReplyMatcher:
    return ReplyMatcher()


def test_a_reply_goes_to_the_request_whose_seq_it_echoes(matcher: ReplyMatcher) -> None:
    first, second = _submit(matcher, GetAngles()), _submit(matcher, GetAngles())
    assert (first.seq, second.seq) == (FIRST_SEQ, FIRST_SEQ + 1)
    _feed(matcher, _reply(AnglesReply(0, 1, 2, 0, 0), second.seq))
    assert second.done and not first.done and matcher.seq_echoed
    _feed(matcher, _reply(AnglesReply(0, 1, 1, 0, 0), first.seq))
    assert first.done and first.packet is not None and first.packet.seq == first.seq


def test_a_retry_keeps_its_seq_and_an_answer_to_either_attempt_completes_it(matcher: ReplyMatcher) -> None:
    waiter = _submit(matcher, GetAngles())
    matcher.expect(waiter)  # the resend: same SEQ, still one waiter
    _feed(matcher, _reply(AnglesReply(0, 1, 5, 0, 0), waiter.seq))
    assert waiter.done
    _feed(matcher, _reply(AnglesReply(0, 1, 5, 0, 0), waiter.seq))  # the second attempt's reply
    assert matcher.stats["stale_replies"] == 1


def test_the_replies_to_a_stops_resends_never_answer_the_next_stop(matcher: ReplyMatcher) -> None:
    """The final stop is resent until answered, and a slow gimbal answers every copy: those extra
    replies are duplicates, not evidence that it stopped echoing SEQs, so the release sent next
    is not paired with one of them, and nobody is blamed for a misattribution."""
    _feed(matcher, _reply(SpeedControlReply(0), _submit(matcher, SpeedControl()).seq))  # echoing learnt
    stop = _submit(matcher, SpeedControl())
    for _ in range(ECHO_EVIDENCE):
        matcher.expect(stop)  # resent
    _feed(matcher, _reply(SpeedControlReply(0), stop.seq))
    release = _submit(matcher, SpeedControl())
    for _ in range(ECHO_EVIDENCE):
        _feed(matcher, _reply(SpeedControlReply(0), stop.seq))
    assert not release.done and matcher.seq_echoed
    assert matcher.stats["duplicate_replies"] == ECHO_EVIDENCE
    _feed(matcher, _reply(SpeedControlReply(0), release.seq))
    assert release.done and matcher.stats["misattributed_replies"] == 0
    _feed(matcher, _reply(SpeedControlReply(0), stop.seq))  # one more than was sent: stale again
    assert matcher.stats["duplicate_replies"] == ECHO_EVIDENCE and matcher.stats["stale_replies"] == ECHO_EVIDENCE + 1


def test_a_late_reply_is_counted_late_and_never_answers_a_newer_request(matcher: ReplyMatcher) -> None:
    old = _submit(matcher, SpeedControl())
    matcher.cancel(old)  # timed out
    new = _submit(matcher, SpeedControl())
    _feed(matcher, _reply(SpeedControlReply(0), old.seq))
    assert not new.done and old.done and old.late  # answered late, for whoever still looks
    assert matcher.stats["late_replies"] == 1 and matcher.stats["stale_replies"] == 1
    assert matcher.stats["misattributed_replies"] == 0 and matcher.seq_echoed
    _feed(matcher, _reply(SpeedControlReply(0), new.seq))
    assert new.done


def test_the_seq_of_a_request_given_up_on_is_not_handed_out_again(matcher: ReplyMatcher) -> None:
    old = _submit(matcher, GetAngles())
    matcher.cancel(old)
    matcher.next_seq = old.seq
    assert _submit(matcher, GetAngles()).seq == old.seq + 1


def test_only_the_latest_requests_given_up_on_are_remembered(matcher: ReplyMatcher) -> None:
    given_up = [_submit(matcher, GetAngles()) for _ in range(GIVEN_UP_KEPT + 1)]
    for waiter in given_up:
        matcher.cancel(waiter)
    _feed(matcher, _reply(AnglesReply(0, 1, 0, 0, 0), given_up[0].seq))  # forgotten: merely stale
    _feed(matcher, _reply(AnglesReply(0, 1, 0, 0, 0), given_up[-1].seq))
    assert matcher.stats["late_replies"] == 1 and matcher.stats["stale_replies"] == 2


def test_an_answered_request_leaves_no_late_reply_behind(matcher: ReplyMatcher) -> None:
    waiter = _submit(matcher, GetAngles())
    _feed(matcher, _reply(AnglesReply(0, 1, 0, 0, 0), waiter.seq))
    matcher.cancel(waiter)  # what request() does once it has its reply
    _feed(matcher, _reply(AnglesReply(0, 1, 0, 0, 0), waiter.seq))
    assert matcher.stats["late_replies"] == 0 and matcher.stats["stale_replies"] == 1


def test_a_reply_for_another_command_does_not_complete_a_request(matcher: ReplyMatcher) -> None:
    waiter = _submit(matcher, GetAngles())
    _feed(matcher, _reply(SpeedControlReply(0), waiter.seq))  # our SEQ, another command's reply
    assert not waiter.done and matcher.stats["stale_replies"] == 1


def test_a_version_reply_naming_another_device_does_not_answer(matcher: ReplyMatcher) -> None:
    waiter = _submit(matcher, VersionQuery(1))
    _feed(matcher, _reply(VersionReply(0, 2, 0x01020304), waiter.seq))
    assert not waiter.done
    _feed(matcher, _reply(VersionReply(0, 1, 0x01020304), waiter.seq))
    assert waiter.done


def test_before_the_first_echo_replies_pair_by_command_then_by_seq_only(matcher: ReplyMatcher) -> None:
    first = _submit(matcher, GetAngles())
    _feed(matcher, _reply(AnglesReply(0, 1, 0, 0, 0), 0x0001))  # a gimbal that does not echo (yet)
    assert first.done and not matcher.seq_echoed
    second = _submit(matcher, GetAngles())
    _feed(matcher, _reply(AnglesReply(0, 1, 0, 0, 0), second.seq))
    assert second.done and matcher.seq_echoed
    third = _submit(matcher, GetAngles())
    _feed(matcher, _reply(AnglesReply(0, 1, 0, 0, 0), 0x0001))
    assert not third.done and matcher.stats["stale_replies"] == 1


def test_replies_that_keep_not_echoing_switch_back_to_pairing_by_command(matcher: ReplyMatcher) -> None:
    matcher.seq_echoed = True
    waiter = _submit(matcher, GetAngles())
    for _ in range(ECHO_EVIDENCE - 1):
        _feed(matcher, _reply(AnglesReply(0, 1, 0, 0, 0), 0x0001))
    assert not waiter.done
    _feed(matcher, _reply(AnglesReply(0, 1, 0, 0, 0), 0x0001))
    assert waiter.done and not matcher.seq_echoed


def test_our_own_reply_after_another_hosts_shows_the_misattribution(matcher: ReplyMatcher) -> None:
    ours = _submit(matcher, GetAngles())
    _feed(matcher, _reply(AnglesReply(0, 1, 111, 0, 0), 0x0005))  # another host's, paired by command
    assert ours.done
    _feed(matcher, _reply(AnglesReply(0, 1, 222, 0, 0), ours.seq))
    assert matcher.stats["misattributed_replies"] == 1 and matcher.seq_echoed


def test_legacy_replies_go_to_the_request_whose_seq_they_echo(matcher: ReplyMatcher) -> None:
    first, second = _submit(matcher, GetAngles()), _submit(matcher, GetAngles())
    _feed(matcher, _reply(AnglesReply(0, 1, 0, 0, 0), second.seq, legacy=True))
    assert second.done and not first.done


def test_pushes_commands_other_ids_and_short_replies_are_not_replies(matcher: ReplyMatcher) -> None:
    waiter = _submit(matcher, GetAngles())
    _feed(matcher, message_packet(ParameterPush(0x01, 1, 2, 3), waiter.seq))
    _feed(matcher, message_packet(GetAngles(), waiter.seq))  # a command (another host's)
    _feed(matcher, _reply(AnglesReply(0, 1, 0, 0, 0), waiter.seq), arbitration_id=HOST_TX_ID)
    assert not waiter.done and matcher.stats["ignored"] == 1
    _feed(matcher, Packet(cmd_type=REPLY_CMD_TYPE, seq=waiter.seq, data=b"\x0e"))
    assert matcher.stats["bad_replies"] == 1 and not waiter.done


def test_undecodable_bytes_are_counted(matcher: ReplyMatcher) -> None:
    matcher.on_message_received(can.Message(arbitration_id=HOST_RX_ID, is_extended_id=False,
                                            data=b"\x01\x02\x03"))
    assert sum(v for k, v in matcher.stats.items() if k.startswith("dropped_")) == 3


def test_fail_all_ends_every_wait(matcher: ReplyMatcher) -> None:
    waiters = [_submit(matcher, GetAngles()) for _ in range(3)]
    error = RuntimeError("bus gone")
    matcher.fail_all(error)
    assert all(w.done and w.error is error for w in waiters)


# Issue #26 item 5: replies that arrive after their command was given up on (``sim --delay-ms 150``)
# are counted as late and dropped; they never answer a newer command, and nobody blames another host.
DELAY_S = 0.15  # every reply, as with `gimbaltrack sim --delay-ms 150`


def test_a_late_reply_never_answers_a_newer_request(channel: str, peer: ScriptedPeer,
                                                    caplog: pytest.LogCaptureFixture) -> None:
    numbers = itertools.count(1)
    peer.answer(GetAngles, lambda request: AnglesReply(0, 1, next(numbers), 0, 0), delay=DELAY_S)
    with caplog.at_level(logging.WARNING), \
            GimbalClient(interface="virtual", channel=channel, timeout=0.1, retries=0) as client:
        for _ in range(3):
            with pytest.raises(GimbalTimeoutError):
                client.request(GetAngles())
        poll(lambda: client.stats["late_replies"] == 3)
        assert client.stats["misattributed_replies"] == 0
        peer.answer(GetAngles, AnglesReply(0, 1, 42, 0, 0))  # on time again
        assert client.request(GetAngles()).yaw == 42
    assert "another host" not in caplog.text


def test_a_slow_gimbal_under_the_keep_alive_gets_no_reply_paired_with_a_newer_command(
        channel: str, peer: ScriptedPeer, caplog: pytest.LogCaptureFixture) -> None:
    """At 25 Hz every reply misses its command's 40 ms window: each is late, none is taken for
    a newer command's, and the late ones show the gimbal hears us, so streaming goes on."""
    peer.answer(SpeedControl, delay=DELAY_S)
    with caplog.at_level(logging.WARNING), GimbalClient(interface="virtual", channel=channel) as client:
        streamer = client.speed_streamer(rate_hz=25.0, max_age=60.0)
        streamer.set(10.0, 0.0)
        poll(lambda: streamer.stats["late_replies"] >= 20)
        assert streamer.error is None and streamer.running
        health = streamer.watchdog.snapshot()
        assert (health.state, health.unanswered, health.episodes) == (ENGAGED, 0, 0)
        streamer.stop()
        assert streamer.stats["replies"] == 0
        assert client.stats["late_replies"] >= streamer.stats["late_replies"]
        assert client.stats["misattributed_replies"] == 0
    assert "another host" not in caplog.text


def test_a_gimbal_that_goes_silent_after_answering_late_is_released(channel: str, peer: ScriptedPeer) -> None:
    peer.answer(SpeedControl, delay=DELAY_S)
    with GimbalClient(interface="virtual", channel=channel) as client:
        streamer = client.speed_streamer(rate_hz=25.0, max_age=60.0, bus_timeout=0.6)
        streamer.set(10.0, 0.0)
        poll(lambda: streamer.stats["late_replies"] >= 3)
        peer.silence(SpeedControl)
        poll(lambda: streamer.watchdog.poll() == DISENGAGED)
        poll(lambda: streamer.stats["probes"] >= 1)
        assert streamer.stats["unanswered"] >= 10 and streamer.error is None
