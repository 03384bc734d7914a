"""GimbalClient against a scripted peer on python-can's virtual bus."""
from __future__ import annotations

import logging
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

import can
import pytest

from gimbal.client import Angles, GimbalClient
from gimbal.errors import BusError, GimbalError, GimbalTimeoutError, RangeError, ReturnCodeError
from gimbal.log_decode import decode_frames
from gimbal.matcher import ECHO_EVIDENCE
from gimbal.messages import Message, decode_message, message_packet
from gimbal.messages.camera import CameraAction, CameraStatusQuery, CameraStatusReply
from gimbal.messages.external import (
    DialPush, FocusCalibration, FocusCalibrationReply, FocusPositionControl, FocusPositionQuery,
    FocusPositionReply, JoystickPush,
)
from gimbal.messages.motion import AnglesReply, GetAngles, PositionControl, SpeedControl
from gimbal.messages.settings import (
    ActiveTrack, AngleLimitsReply, GetAngleLimits, GetMotorStiffness, MotorStiffnessReply, RecenterSelfie,
    SetAngleLimits, SetFollowMode, SetMotorStiffness, SetWorkMode,
)
from gimbal.messages.telemetry import ParameterPush, PushControl, VersionPush, VersionQuery, VersionReply
from gimbal.messages.tlv_params import (
    AutoCalibration, CalibrationStatusPush, GetUserParams, SetUserParams, SetUserParamsReply, Tlv,
    UserParamsReply, motors_off,
)
from gimbal.packet import Packet, REPLY_CMD_TYPE, encode_packet
from gimbal.signals import deferred_signals, exit_on_signals
from tests.gimbal.scripted_peer import FlakyBus, RELEASE, ScriptedPeer, ZERO, poll, speed_messages
from tests.gimbal.test_log_decode import frames_of


DOC_EXAMPLE = bytes.fromhex("AA 1A 00 03 00 00 00 00 22 11 A2 42 0E 00 20 00 30 00 40 00 01 14 7B 40 97 BE")


@pytest.fixture
def client(channel: str, peer: ScriptedPeer) -> Iterator[GimbalClient]:
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=1) as gimbal:
        yield gimbal


def test_first_request_is_the_documents_example(client: GimbalClient, peer: ScriptedPeer) -> None:
    peer.answer(PositionControl)
    client.position(yaw=3.2, roll=4.8, pitch=6.4, absolute=True, time_s=2)
    assert encode_packet(peer.received[0].packet) == DOC_EXAMPLE


# (call, command class, reply to give, expected DATA bytes, expected CmdType, check on the result)
REQUESTS: list[tuple[Callable[[GimbalClient], Any], type[Message], Message | None, str, int,
                     Callable[[Any], bool]]] = [
    (lambda c: c.position(yaw=-1.26, axes=("yaw",), absolute=False, time_s=0.5), PositionControl,
     None, "0E 00 F3FF 0000 0000 0C 05", 0x03, lambda r: r is None),
    (lambda c: c.speed(10, -5, 1), SpeedControl, None, "0E 01 6400 0A00 CEFF 88", 0x03,
     lambda r: r is None),
    (lambda c: c.speed(0, 0, take_control=False), SpeedControl, None, "0E 01 0000 0000 0000 08",
     0x03, lambda r: r is None),
    (lambda c: c.get_angles("joint"), GetAngles, AnglesReply(0, 2, -900, 15, 1234), "0E 02 02",
     0x03, lambda r: r == Angles("joint", -90.0, 1.5, 123.4)),
    (lambda c: c.set_angle_limits(145, 55, 179, 179, 30, 30), SetAngleLimits, None,
     "0E 03 01 91 37 B3 B3 1E 1E", 0x03, lambda r: r is None),
    (lambda c: c.get_angle_limits(), GetAngleLimits, AngleLimitsReply(0, 100, 40, 90, 80, 20, 10),
     "0E 04 01", 0x03, lambda r: (r.pitch_max, r.roll_min) == (100, 10)),
    (lambda c: c.set_stiffness(10, 20, 30), SetMotorStiffness, None, "0E 05 01 0A 14 1E", 0x03,
     lambda r: r is None),
    (lambda c: c.get_stiffness(), GetMotorStiffness, MotorStiffnessReply(0, 10, 30, 20), "0E 06 01",
     0x03, lambda r: (r.pitch_stiffness, r.yaw_stiffness, r.roll_stiffness) == (10, 30, 20)),
    (lambda c: c.set_push(True), PushControl, None, "0E 07 01", 0x03, lambda r: r is None),
    (lambda c: c.set_push(False), PushControl, None, "0E 07 02", 0x03, lambda r: r is None),
    (lambda c: c.version(), VersionQuery, VersionReply(0, 1, 0x01020304), "0E 09 01000000", 0x03,
     lambda r: r.version_text == "01.02.03.04"),
    (lambda c: c.get_user_params([0x23]), GetUserParams, UserParamsReply(0, (Tlv(0x23, b"\x01"),)),
     "0E 0B 23", 0x03, lambda r: r == (Tlv(0x23, b"\x01"),)),
    (lambda c: c.set_user_params([motors_off(True)]), SetUserParams,
     SetUserParamsReply(0, (Tlv(0x23, b"\x01"),)), "0E 0C 23 01 01", 0x03,
     lambda r: r == (Tlv(0x23, b"\x01"),)),
    (lambda c: c.set_work_mode("portrait"), SetWorkMode, None, "0E 0D FE 03", 0x03,
     lambda r: r is None),
    (lambda c: c.recenter(), RecenterSelfie, None, "0E 0E FE 01", 0x03, lambda r: r is None),
    (lambda c: c.selfie(), RecenterSelfie, None, "0E 0E FE 02", 0x03, lambda r: r is None),
    (lambda c: c.set_follow_mode("fpv"), SetFollowMode, None, "0E 0E 03 00", 0x03,
     lambda r: r is None),
    (lambda c: c.auto_calibration(True, 1), AutoCalibration, None, "0E 0F 00 01 03", 0x01,
     lambda r: r is None),
    (lambda c: c.activetrack_toggle(), ActiveTrack, None, "0E 11 03", 0x01, lambda r: r is None),
    (lambda c: c.focus_calibration("auto"), FocusCalibration, FocusCalibrationReply(0, 2, 0, 1),
     "0E 12 02 00 01", 0x03, lambda r: r is False),
    (lambda c: c.focus_read(), FocusPositionQuery, FocusPositionReply(0, 0x15, 0, 3, 1234),
     "0E 12 15 00", 0x03, lambda r: (r.calibration_state, r.position) == (3, 1234)),
    (lambda c: c.photo(), CameraAction, None, "0D 00 0100", 0x03, lambda r: r is None),
    (lambda c: c.start_recording(), CameraAction, None, "0D 00 0300", 0x03, lambda r: r is None),
    (lambda c: c.stop_recording(), CameraAction, None, "0D 00 0400", 0x03, lambda r: r is None),
    (lambda c: c.camera_action(5), CameraAction, None, "0D 00 0500", 0x03, lambda r: r is None),
    (lambda c: c.camera_status(), CameraStatusQuery, CameraStatusReply(0, 2), "0D 01 01", 0x03,
     lambda r: r is True),
]


@pytest.mark.parametrize("call,cls,reply,data,cmd_type,check", REQUESTS,
                         ids=[f"{r[1].__name__}-{i}" for i, r in enumerate(REQUESTS)])
def test_typed_requests_send_the_documents_bytes_and_parse_replies(
        client: GimbalClient, peer: ScriptedPeer, call: Callable[[GimbalClient], Any],
        cls: type[Message], reply: Message | None, data: str, cmd_type: int,
        check: Callable[[Any], bool]) -> None:
    peer.answer(cls, reply)
    result = call(client)
    sent = peer.received[-1].packet
    assert sent.data == bytes.fromhex(data)
    assert sent.cmd_type == cmd_type
    assert check(result), result


PUSHES: list[tuple[Callable[[GimbalClient], None], type[Message], str]] = [
    (lambda c: c.push_version(2, 0x01000000), VersionPush, "0E 09 02000000 00000001"),
    (lambda c: c.joystick(yaw=100, pitch=-200), JoystickPush, "0E 0A 01 38FF 0000 6400"),
    (lambda c: c.dial(-2048), DialPush, "0E 0A 02 00F8"),
    (lambda c: c.focus_position(4095), FocusPositionControl, "0E 12 01 00 02 FF0F"),
]


@pytest.mark.parametrize("call,cls,data", PUSHES, ids=[p[1].__name__ for p in PUSHES])
def test_host_pushes_go_out_with_cmd_type_zero_and_wait_for_nothing(
        client: GimbalClient, peer: ScriptedPeer, call: Callable[[GimbalClient], None],
        cls: type[Message], data: str) -> None:
    call(client)  # the peer never answers: this returns without waiting
    peer.wait_for(cls)
    sent = peer.received[-1].packet
    assert (sent.data, sent.cmd_type) == (bytes.fromhex(data), 0x00)


def test_out_of_range_values_raise_before_anything_is_sent(client: GimbalClient,
                                                          peer: ScriptedPeer) -> None:
    for call in (lambda: client.position(yaw=180.1), lambda: client.position(pitch=-56.1),
                 lambda: client.speed(360.1, 0), lambda: client.speed(float("nan"), 0),
                 lambda: client.set_stiffness(101, 0, 0), lambda: client.focus_position(4096),
                 lambda: client.set_follow_mode("sideways"), lambda: client.get_angles("euler"),
                 lambda: client.position(time_s=25.6), lambda: client.joystick(15001, 0)):
        with pytest.raises(RangeError):
            call()
    assert peer.received == []


def test_silence_raises_a_timeout_error_after_the_retries_with_the_same_seq(
        client: GimbalClient, peer: ScriptedPeer) -> None:
    peer.silence(GetAngles)
    with pytest.raises(GimbalTimeoutError) as raised:
        client.get_angles()
    assert isinstance(raised.value, TimeoutError)
    sent = [r.packet for r in peer.received]
    assert len(sent) == 2 and sent[0] == sent[1]  # retries=1: two identical packets


def test_a_retry_recovers_a_lost_reply(client: GimbalClient, peer: ScriptedPeer) -> None:
    peer.answer(GetAngles, AnglesReply(0, 1, 10, 20, 30), ignore_first=1)
    assert client.get_angles() == Angles("attitude", 1.0, 2.0, 3.0)
    assert client.stats["retries"] == 1


@pytest.mark.parametrize("call,cls", [
    (lambda c: c.position(yaw=5, absolute=False), PositionControl),
    (lambda c: c.photo(), CameraAction),
    (lambda c: c.selfie(), RecenterSelfie),
], ids=["relative-move", "photo", "selfie"])
def test_commands_that_must_not_repeat_are_never_retried(
        client: GimbalClient, peer: ScriptedPeer, call: Callable[[GimbalClient], None],
        cls: type[Message]) -> None:
    peer.silence(cls)
    with pytest.raises(GimbalTimeoutError):
        call(client)
    assert len(peer.received) == 1


def test_reply_optional_commands_accept_silence(client: GimbalClient, peer: ScriptedPeer) -> None:
    peer.silence(ActiveTrack)
    client.activetrack_toggle()
    assert len(peer.received) == 1


@pytest.mark.parametrize("code,meaning", [(0x01, "could not be parsed"),
                                          (0x02, "could not be executed"),
                                          (0xFF, "undefined error"),
                                          (0x7F, "not defined by the document")])
@pytest.mark.parametrize("legacy", [False, True], ids=["latest", "legacy"])
def test_nack_return_codes_are_raised_with_their_meaning(
        client: GimbalClient, peer: ScriptedPeer, code: int, meaning: str, legacy: bool) -> None:
    peer.nack(GetAngleLimits, code, legacy=legacy)
    with pytest.raises(ReturnCodeError, match=meaning) as raised:
        client.get_angle_limits()
    assert raised.value.return_code == code
    assert len(peer.received) == 1  # a NACK is an answer: no retry


def test_legacy_layout_replies_are_parsed(client: GimbalClient, peer: ScriptedPeer) -> None:
    peer.answer(GetAngles, AnglesReply(0, 1, -100, 0, 250), legacy=True)
    assert client.get_angles() == Angles("attitude", -10.0, 0.0, 25.0)


def test_replies_without_the_requests_seq_match_by_command(client: GimbalClient,
                                                           peer: ScriptedPeer) -> None:
    peer.answer(GetAngles, AnglesReply(0, 1, 1, 2, 3), seq=0x0001)  # firmware that ignores SEQ
    assert client.get_angles().yaw == pytest.approx(0.1)
    peer.answer(CameraStatusQuery, CameraStatusReply(0, 0), seq=0x0001, legacy=True)
    assert client.camera_status() is False


def test_late_replies_are_dropped_as_stale(client: GimbalClient, peer: ScriptedPeer) -> None:
    peer.answer(VersionQuery, VersionReply(0, 1, 0x01000000))
    client.version()  # the gimbal echoes SEQs: later unknown SEQs are stale
    peer.answer(GetAngles, AnglesReply(0, 1, 111, 0, 0), delay=0.4)
    with pytest.raises(GimbalTimeoutError):
        client.request(GetAngles(), timeout=0.05, retries=0)
    # the late reply arrives while this request waits for its own, slower one
    peer.answer(GetAngles, AnglesReply(0, 1, 222, 0, 0), delay=0.8)
    assert client.request(GetAngles(), timeout=3.0, retries=0).yaw == 222
    assert client.stats["stale_replies"] == 1


@pytest.mark.parametrize("data", [b"\x0e", b"\x0d"], ids=["0x0E", "0x0D"])
def test_a_reply_too_short_for_cmdset_and_cmdid_is_counted_and_dropped(
        client: GimbalClient, peer: ScriptedPeer, data: bytes) -> None:
    peer.transport.send(Packet(cmd_type=REPLY_CMD_TYPE, seq=0x0007, data=data))
    poll(lambda: client.stats["bad_replies"] == 1)
    assert client.alive
    peer.answer(GetAngleLimits, AngleLimitsReply(0, 1, 2, 3, 4, 5, 6))
    assert client.get_angle_limits().pitch_max == 1


def test_concurrent_requests_get_their_own_replies(client: GimbalClient, peer: ScriptedPeer) -> None:
    peer.answer(GetAngles, lambda m: AnglesReply(0, m.ctrl_byte, m.ctrl_byte * 100, 0, 0))
    results: dict[str, Angles] = {}

    def ask(kind: str) -> None:
        for _ in range(20):
            results[kind] = client.get_angles(kind)
            assert results[kind].kind == kind
            assert results[kind].yaw == (10.0 if kind == "attitude" else 20.0)

    threads = [threading.Thread(target=ask, args=(k,)) for k in ("attitude", "joint")]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert set(results) == {"attitude", "joint"}


def test_pushes_reach_callbacks_with_arrival_times(client: GimbalClient, peer: ScriptedPeer) -> None:
    got: list[tuple[Message, float]] = []
    client.on_push(ParameterPush, lambda m, t: got.append((m, t)))
    assert client.latest(ParameterPush) is None
    before = time.monotonic()
    push = ParameterPush(0x01, 10, 20, 30, 40, 50, 60)  # a short push: limits and stiffness absent
    peer.push(push, cmd_type=0x20)  # some firmware sets the reply bit on pushes
    poll(lambda: len(got) == 1)
    message, t = got[0]
    assert message.yaw_angle == 10 and message.pitch_stiffness is None and message.angles_valid
    assert before <= t <= time.monotonic()
    assert client.latest(ParameterPush) == (message, t)


def test_wait_for_push_returns_the_next_one(client: GimbalClient, peer: ScriptedPeer) -> None:
    status = CalibrationStatusPush.of(1, 42)
    threading.Timer(0.05, peer.push, (status,)).start()
    message, _ = client.wait_for_push(CalibrationStatusPush, timeout=5.0)
    assert (message.state, message.progress) == (1, 42)
    with pytest.raises(GimbalTimeoutError):
        client.wait_for_push(CalibrationStatusPush, timeout=0.05)
    with pytest.raises(ValueError):
        client.on_push(GetAngles, lambda m, t: None)


def test_a_failing_callback_is_logged_and_does_not_stop_delivery(
        client: GimbalClient, peer: ScriptedPeer, caplog: pytest.LogCaptureFixture) -> None:
    def broken(message: Message, t: float) -> None:
        raise RuntimeError("user bug")

    got: list[Message] = []
    client.on_push(ParameterPush, broken)
    client.on_push(ParameterPush, lambda m, t: got.append(m))
    with caplog.at_level(logging.ERROR, logger="gimbal.pushes"):
        peer.push(ParameterPush(0x01, 1, 2, 3, 4, 5, 6))
        peer.push(ParameterPush(0x01, 7, 8, 9, 10, 11, 12))
        poll(lambda: len(got) == 2)
    assert "user bug" in caplog.text
    peer.answer(GetAngleLimits, AngleLimitsReply(0, 1, 2, 3, 4, 5, 6))
    assert client.get_angle_limits().pitch_max == 1  # the receive thread is alive


def test_a_dead_receive_thread_is_raised_on_the_next_call_and_stops_the_gimbal(
        channel: str, peer: ScriptedPeer) -> None:
    bus = FlakyBus(channel=channel)
    peer.answer(SpeedControl)
    with GimbalClient(bus, timeout=0.2) as gimbal:
        gimbal.speed(20, 0)
        bus.fail_recv = True
        poll(lambda: not gimbal.alive)
        with pytest.raises(BusError, match="adapter gone"):
            gimbal.get_angles()
        poll(lambda: speed_messages(peer)[-2:] == [ZERO, RELEASE])
    bus.shutdown()


def test_a_receive_error_that_passes_does_not_lose_the_bus(channel: str, peer: ScriptedPeer) -> None:
    """One failed receive once marked the bus lost for good, though it worked again at once."""
    bus = FlakyBus(channel=channel)
    peer.answer(GetAngles, AnglesReply(0, 1, 10, 20, 30))
    with GimbalClient(bus, timeout=0.2) as gimbal:
        bus.fail_recv = True
        poll(lambda: gimbal.stats["receive_errors"] >= 1)
        bus.fail_recv = False
        assert gimbal.alive and gimbal.get_angles().yaw == 1.0
    bus.shutdown()


def test_leaving_the_client_stops_and_releases_speed_control(client: GimbalClient,
                                                             peer: ScriptedPeer) -> None:
    peer.answer(SpeedControl)
    client.speed(30, -10)
    client.close()
    assert speed_messages(peer) == [(300, 0, -100, 0x88), ZERO, RELEASE]
    client.close()  # idempotent
    assert len(speed_messages(peer)) == 3


def test_an_exception_inside_the_context_still_sends_the_safety_stop(
        channel: str, peer: ScriptedPeer) -> None:
    peer.answer(SpeedControl)
    with pytest.raises(KeyboardInterrupt):
        with GimbalClient(interface="virtual", channel=channel) as gimbal:
            gimbal.speed(0, 15)
            raise KeyboardInterrupt
    assert speed_messages(peer)[-2:] == [ZERO, RELEASE]


def test_sigterm_becomes_a_clean_exit_with_the_safety_stop(channel: str, peer: ScriptedPeer) -> None:
    peer.answer(SpeedControl)
    previous = signal.getsignal(signal.SIGTERM)
    with pytest.raises(SystemExit) as raised:
        with exit_on_signals(), GimbalClient(interface="virtual", channel=channel) as gimbal:
            gimbal.speed(0, 15)
            signal.raise_signal(signal.SIGTERM)
    assert raised.value.code == 128 + signal.SIGTERM
    assert speed_messages(peer)[-2:] == [ZERO, RELEASE]
    assert signal.getsignal(signal.SIGTERM) is previous


def test_signals_in_a_deferred_block_arrive_once_when_it_ends() -> None:
    done = []
    previous = signal.getsignal(signal.SIGTERM)
    with pytest.raises(SystemExit) as raised:
        with exit_on_signals(), deferred_signals():
            signal.raise_signal(signal.SIGTERM)
            signal.raise_signal(signal.SIGTERM)
            done.append("the rest of the block")
    assert done == ["the rest of the block"] and raised.value.code == 128 + signal.SIGTERM
    assert signal.getsignal(signal.SIGTERM) is previous
    with pytest.raises(KeyboardInterrupt):
        with deferred_signals():
            signal.raise_signal(signal.SIGINT)
            done.append("finished before Ctrl-C lands")
    assert done[-1] == "finished before Ctrl-C lands"


def test_signals_during_a_clean_up_are_dropped() -> None:
    """The clean-up after a stop (deliver=False) runs to its end whatever else arrives."""
    done = []
    with exit_on_signals(), deferred_signals(deliver=False):
        signal.raise_signal(signal.SIGINT)
        signal.raise_signal(signal.SIGTERM)
        done.append("outputs finalised")
    assert done == ["outputs finalised"]


def test_no_speed_command_on_exit_when_speed_was_never_used(client: GimbalClient,
                                                            peer: ScriptedPeer) -> None:
    peer.answer(PushControl)
    client.set_push(True)
    client.close()
    assert speed_messages(peer) == []


def test_only_buses_the_client_built_are_shut_down(channel: str, peer: ScriptedPeer) -> None:
    with GimbalClient(interface="virtual", channel=channel) as built:
        pass
    with pytest.raises(can.CanOperationError):
        built.bus.send(can.Message(arbitration_id=1))
    given = can.Bus(interface="virtual", channel=channel)
    with GimbalClient(given):
        pass
    given.send(can.Message(arbitration_id=1))  # still open
    given.shutdown()


@pytest.mark.parametrize("timeout", [0.0, -1.0, float("nan"), float("inf")])
def test_a_timeout_that_cannot_be_waited_for_is_refused(channel: str, timeout: float) -> None:
    bus = can.Bus(interface="virtual", channel=channel)
    with pytest.raises(ValueError, match="timeout must be above 0"):
        GimbalClient(bus, timeout=timeout)
    bus.shutdown()


def test_an_unconfigured_bus_is_a_bus_error(monkeypatch: pytest.MonkeyPatch, tmp_path: Any) -> None:
    monkeypatch.setattr(can, "rc", {})
    monkeypatch.setenv("HOME", str(tmp_path))
    for name in ("CAN_INTERFACE", "CAN_CHANNEL", "CAN_BITRATE", "CAN_CONFIG"):
        monkeypatch.delenv(name, raising=False)
    with pytest.raises(BusError, match="cannot open the CAN bus"):
        GimbalClient()


def test_the_zero_push_still_goes_out_once_the_receive_side_is_lost(channel: str, peer: ScriptedPeer) -> None:
    """Joystick and dial pushes have no timeout on the gimbal: their zero must not be refused
    because the bus stopped answering."""
    bus = FlakyBus(channel=channel)
    with GimbalClient(bus, timeout=0.2) as gimbal:
        gimbal.joystick(5000, 0)
        bus.fail_recv = True
        poll(lambda: not gimbal.alive)
        with pytest.raises(BusError):
            gimbal.joystick(5000, 0)
        gimbal.send_best_effort(JoystickPush())
        poll(lambda: len(peer.messages(JoystickPush)) == 2)
        assert [m.yaw_speed for m in peer.messages(JoystickPush)] == [5000, 0]
        bus.fail_send = True
        gimbal.send_best_effort(JoystickPush())  # logged, not raised
    bus.shutdown()


def test_a_seq_matched_by_chance_does_not_make_the_client_deaf(channel: str, peer: ScriptedPeer) -> None:
    """A gimbal that answers with a fixed SEQ: once the client's counter reached it, one chance
    match made every later reply stale for good. Now it costs the next request two attempts."""
    peer.answer(VersionQuery, VersionReply(0, 1, 7), seq=0x2000)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=2) as gimbal:
        gimbal.replies.next_seq = 0x2000 - 2  # the counter about to pass the gimbal's fixed SEQ
        assert all(gimbal.version().version == 7 for _ in range(8))
        assert gimbal.stats["stale_replies"] == ECHO_EVIDENCE - 1


def test_a_gimbal_that_stops_echoing_is_paired_by_command_again(client: GimbalClient,
                                                                 peer: ScriptedPeer) -> None:
    peer.answer(VersionQuery, VersionReply(0, 1, 7))
    client.version()
    assert client.replies.seq_echoed
    peer.answer(VersionQuery, VersionReply(0, 1, 7), seq=0x0001)  # e.g. a firmware update
    with pytest.raises(GimbalTimeoutError):  # both attempts' replies taken for late ones
        client.version()
    assert client.version().version == 7  # the third in a row: paired by command from here on
    assert not client.replies.seq_echoed and client.stats["stale_replies"] == ECHO_EVIDENCE - 1


def test_close_from_another_thread_leaves_the_stop_as_the_last_speed_command(
        channel: str, peer: ScriptedPeer) -> None:
    """A thread sending speed() while another closed the client once sent 30 deg/s after the release."""
    peer.answer(SpeedControl)
    gimbal = GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=0)
    refused: list[BaseException] = []

    def keep_turning() -> None:
        try:
            while True:
                gimbal.speed(30.0, 0.0)
        except GimbalError as exc:
            refused.append(exc)

    turner = threading.Thread(target=keep_turning)
    turner.start()
    peer.wait_for(SpeedControl, count=5)
    gimbal.close()
    turner.join(5.0)
    assert refused and not turner.is_alive()
    assert speed_messages(peer)[-2:] == [ZERO, RELEASE]


def test_close_from_a_push_callback_closes_and_shuts_the_bus_down(channel: str, peer: ScriptedPeer) -> None:
    gimbal = GimbalClient(interface="virtual", channel=channel)
    gimbal.on_push(CalibrationStatusPush, lambda message, t: gimbal.close())
    peer.push(CalibrationStatusPush.of(1, 42))
    poll(lambda: not gimbal.alive)
    poll(lambda: gimbal.bus._is_shutdown)


def test_a_request_from_a_push_callback_is_refused_at_once(client: GimbalClient, peer: ScriptedPeer) -> None:
    errors: list[BaseException] = []

    def ask(message: Message, t: float) -> None:
        try:
            client.version()
        except GimbalError as exc:
            errors.append(exc)

    client.on_push(CalibrationStatusPush, ask)
    peer.push(CalibrationStatusPush.of(1, 42))
    poll(lambda: len(errors) == 1)
    assert "push callback" in str(errors[0]) and not isinstance(errors[0], GimbalTimeoutError)


@pytest.mark.parametrize("ending", ["close", "bus lost"])
def test_wait_for_push_ends_when_the_client_closes_or_loses_the_bus(channel: str, peer: ScriptedPeer,
                                                                      ending: str) -> None:
    gimbal = GimbalClient(FlakyBus(channel=channel))
    end = gimbal.close if ending == "close" else lambda: setattr(gimbal.bus, "fail_recv", True)
    timer = threading.Timer(0.1, end)
    timer.start()
    try:
        with pytest.raises(GimbalError) as error:
            gimbal.wait_for_push(CalibrationStatusPush, timeout=30.0)
        assert not isinstance(error.value, GimbalTimeoutError)
    finally:
        timer.join()
        gimbal.close()
        gimbal.bus.shutdown()


class _OSErrorBus(FlakyBus):
    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        raise OSError(105, "No buffer space available")


def test_a_plain_oserror_from_a_third_party_bus_is_a_bus_error(channel: str) -> None:
    bus = _OSErrorBus(channel=channel)
    with GimbalClient(bus) as gimbal, pytest.raises(BusError, match="No buffer space"):
        gimbal.version()
    bus.shutdown()


def test_another_hosts_reply_before_the_first_echo_costs_one_request_only(
        client: GimbalClient, peer: ScriptedPeer) -> None:
    """On a bus shared with another host, a reply to its GetAngles (its own SEQ) can arrive
    before ours while the client has not yet seen the gimbal echo a SEQ: it is paired by command
    (a gimbal that does not echo looks the same). Our own reply, echoing our SEQ, arrives just
    after: that shows the gimbal echoes, so the next foreign reply is stale instead of taken
    again for every later request."""
    foreign = encode_packet(Packet.reply(0x0E, 0x02, bytes((0, 1)) + (111).to_bytes(2, "little", signed=True)
                                         + bytes(4), seq=0x0005))
    peer.answer(GetAngles, AnglesReply(0, 1, 222, 0, 0), delay=0.1)
    first = client.submit(GetAngles())
    peer.transport.send(foreign)
    assert first.wait(2.0) and client.result(first).yaw == 111  # indistinguishable, the first time
    poll(lambda: client.stats["stale_replies"] == 1)  # our own reply, too late
    second = client.submit(GetAngles())
    peer.transport.send(foreign)
    assert second.wait(2.0) and client.result(second).yaw == 222
    assert client.stats["stale_replies"] == 2 and client.stats["misattributed_replies"] == 1


def test_sys_exit_in_a_push_callback_stops_the_gimbal_and_says_so(client: GimbalClient,
                                                                   peer: ScriptedPeer) -> None:
    """``sys.exit()`` in a callback ends the receive thread (it cannot end the program from
    there): the gimbal gets its stop, and later calls name the callback's SystemExit instead of
    an empty "the receive thread stopped: " that reads like a lost bus."""
    peer.answer(SpeedControl)
    client.speed(0, 15)
    client.on_push(ParameterPush, lambda message, t: sys.exit())
    peer.push(ParameterPush(0x01, 10, 20, 30))
    poll(lambda: not client.alive)
    poll(lambda: speed_messages(peer)[-2:] == [ZERO, RELEASE])
    with pytest.raises(BusError, match=r"push callback .* raised SystemExit\(\)"):
        client.get_angles()


def test_the_stop_on_a_lost_bus_comes_after_a_command_already_being_sent(channel: str, peer: ScriptedPeer) -> None:
    """A command another thread is sending when the receive side dies goes out before the
    safety stop, not after it: otherwise the gimbal would run at that speed for its 0.5 s."""
    gimbal = GimbalClient(FlakyBus(channel=channel), timeout=0.2, retries=0)
    peer.answer(SpeedControl)
    gimbal.speed(0, 15)
    send, arrived, go = gimbal.transport.send, threading.Event(), threading.Event()

    def held_send(raw: bytes) -> bytes:
        if threading.current_thread().name == "user":
            arrived.set()  # past the client's checks, on its way to the bus
            go.wait(5.0)
        return send(raw)

    gimbal.transport.send = held_send  # type: ignore[method-assign]
    user = threading.Thread(target=lambda: pytest.raises(GimbalError, gimbal.speed, 30, 0), name="user")
    user.start()
    try:
        assert arrived.wait(5.0)
        gimbal.bus.fail_recv = True
        time.sleep(0.6)  # the receive thread gives up after RX_GIVE_UP_S and stops the gimbal
        go.set()
        user.join(5.0)
        poll(lambda: len(speed_messages(peer)) == 4)
        assert speed_messages(peer)[1:] == [(300, 0, 0, ZERO[3]), ZERO, RELEASE]
    finally:
        go.set()
        gimbal.close()
        gimbal.bus.shutdown()


# Section 2.3.4.10: the version query (0x0E/0x09) names a device (设备 ID) and its reply names
# the device whose version it carries. A reply naming another device answers another query (e.g.
# another host's on a shared bus), never this one: not in the client, not in the log decoder.
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
