"""SpeedStreamer: rate, the max_age rule, stop, latencies and bus loss, against a scripted peer."""
from __future__ import annotations

import time
from collections.abc import Iterator

import pytest

from gimbal.client import GimbalClient
from gimbal.errors import BusError, GimbalError, RangeError
from gimbal.keepalive import STAT_KEYS, SpeedStreamer
from gimbal.messages.motion import SpeedControl
from gimbal.watchdog import DISENGAGED
from tests.gimbal.scripted_peer import (
    RELEASE,
    ZERO,
    FlakyBus,
    ScriptedPeer,
    poll,
    speed_messages,
)


class FakeClock:
    def __init__(self, now: float = 100.0) -> None:
        self.now = now

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def peer(peer: ScriptedPeer) -> ScriptedPeer:
    """The shared scripted peer, answering speed commands."""
    peer.answer(SpeedControl)
    return peer


@pytest.fixture
def client(channel: str, peer: ScriptedPeer) -> Iterator[GimbalClient]:
    with GimbalClient(interface="virtual", channel=channel) as gimbal:
        yield gimbal


def test_the_setpoint_is_resent_at_the_configured_rate(client: GimbalClient, peer: ScriptedPeer) -> None:
    streamer = client.speed_streamer(rate_hz=25.0, max_age=60.0)
    streamer.set(12.3, -4.5, 0.6)
    peer.wait_for(SpeedControl, 30, where=lambda m: m.yaw_speed == 123)
    times = [r.t for r in peer.received if isinstance(r.message, SpeedControl)
             and r.message.yaw_speed == 123]
    rate = (len(times) - 1) / (times[-1] - times[0])
    assert 12 < rate < 40  # 25 Hz with generous bounds for a loaded machine
    message = peer.messages(SpeedControl)[-1]
    assert (message.yaw_speed, message.roll_speed, message.pitch_speed, message.ctrl_byte) \
        == (123, 6, -45, 0x88)
    assert streamer.stats["reply_timeouts"] == 0


def test_a_stale_setpoint_is_never_resent(client: GimbalClient, peer: ScriptedPeer) -> None:
    clock = FakeClock()
    streamer = SpeedStreamer(client, rate_hz=50.0, max_age=0.3, clock=clock)
    try:
        streamer.set(10, 0)
        peer.wait_for(SpeedControl, where=lambda m: m.yaw_speed == 100)
        clock.now += 0.31
        seen = len(peer.messages(SpeedControl))
        peer.wait_for(SpeedControl, seen + 5)
        after = speed_messages(peer)[seen + 1:]  # one send may have read the clock before the jump
        assert after and all(m == ZERO for m in after)
        assert streamer.stats["zero_sent"] >= len(after)
    finally:
        streamer.stop()


def test_setpoints_are_clamped_and_nan_refused(client: GimbalClient, peer: ScriptedPeer) -> None:
    streamer = client.speed_streamer()
    streamer.set(1000, -1000, 400)
    peer.wait_for(SpeedControl, where=lambda m: m.yaw_speed == 3600)
    assert speed_messages(peer)[-1] == (3600, 3600, -3600, 0x88)
    with pytest.raises(RangeError):
        streamer.set(float("nan"), 0)


def test_stop_sends_zero_then_releases_control(client: GimbalClient, peer: ScriptedPeer) -> None:
    streamer = client.speed_streamer()
    streamer.set(5, 5)
    peer.wait_for(SpeedControl, where=lambda m: m.yaw_speed == 50)
    streamer.stop()
    assert speed_messages(peer)[-2:] == [ZERO, RELEASE]
    count = len(peer.messages(SpeedControl))
    with pytest.raises(GimbalError):
        streamer.set(1, 1)
    streamer.stop()
    client.close()  # control already released: nothing more to send
    assert len(peer.messages(SpeedControl)) == count


def test_leaving_the_client_stops_a_running_streamer(channel: str, peer: ScriptedPeer) -> None:
    with pytest.raises(RuntimeError):
        with GimbalClient(interface="virtual", channel=channel) as gimbal:
            streamer = gimbal.speed_streamer()
            streamer.set(0, 20)
            peer.wait_for(SpeedControl, where=lambda m: m.pitch_speed == 200)
            raise RuntimeError("tracker crashed")
    assert not streamer.running
    assert speed_messages(peer)[-2:] == [ZERO, RELEASE]


def test_latency_is_stamp_to_first_send(client: GimbalClient, peer: ScriptedPeer) -> None:
    clock = FakeClock(50.0)
    streamer = SpeedStreamer(client, clock=clock)
    try:
        streamer.set(1, 1, stamp=49.9)
        poll(lambda: len(streamer.latencies()) == 1)
        peer.wait_for(SpeedControl, 5)
        assert streamer.latencies() == [pytest.approx(0.1)]  # counted once, not per resend
    finally:
        streamer.stop()


def test_reply_errors_are_counted_and_streaming_goes_on(client: GimbalClient, peer: ScriptedPeer) -> None:
    peer.nack(SpeedControl, 0x02)
    streamer = client.speed_streamer()
    poll(lambda: streamer.stats["reply_errors"] >= 3)
    assert streamer.running and streamer.error is None
    streamer.set(1, 0)


def test_a_silent_gimbal_is_released_after_the_bus_timeout_and_taken_back_when_it_answers(
        client: GimbalClient, peer: ScriptedPeer) -> None:
    """Issue #26 item 1: ten unanswered commands once ended streaming for good (a BusError at the
    next set(), the run over). Now streaming goes on, the gimbal is stopped and released after the
    watchdog's timeout, probed with releases, and taken back when it answers."""
    peer.silence(SpeedControl)
    streamer = client.speed_streamer(max_age=60.0, bus_timeout=0.6)
    streamer.set(1, 0)
    poll(lambda: streamer.watchdog.poll() == DISENGAGED)
    poll(lambda: streamer.stats["probes"] >= 2)
    assert streamer.running and streamer.error is None
    streamer.set(2, 0)  # the run goes on: setpoints are taken, not sent
    sent = speed_messages(peer)
    first_release = sent.index(RELEASE)
    assert sent[first_release - 1] == ZERO and set(sent[first_release:]) == {RELEASE}
    assert streamer.stats["unanswered"] >= 10 and streamer.stats["disengaged"] == 1
    peer.answer(SpeedControl)
    peer.wait_for(SpeedControl, where=lambda m: m.yaw_speed == 20 and m.ctrl_byte == ZERO[3])
    assert streamer.stats["reengaged"] == 1
    assert streamer.watchdog.snapshot().disengagements == 1


def test_a_send_refused_now_and_then_is_counted_and_streaming_goes_on(channel: str, peer: ScriptedPeer) -> None:
    """One refused send (a full transmit queue: ENOBUFS on socketcan) once ended streaming for good."""
    peer.answer(SpeedControl)
    bus = FlakyBus(channel=channel)
    with GimbalClient(bus) as gimbal:
        streamer = gimbal.speed_streamer(rate_hz=25)
        streamer.set(3, 3)
        peer.wait_for(SpeedControl, where=lambda m: m.yaw_speed == 30)
        bus.fail_send = True
        poll(lambda: streamer.stats["send_errors"] >= 2)
        bus.fail_send = False
        replies = streamer.stats["replies"]
        poll(lambda: streamer.stats["replies"] > replies + 2)
        streamer.set(4, 3)  # still streaming
        assert streamer.error is None
    assert speed_messages(peer)[-2:] == [ZERO, RELEASE]
    bus.shutdown()


def test_a_bus_that_keeps_refusing_disengages_and_resumes_when_it_sends_again(channel: str,
                                                                              peer: ScriptedPeer) -> None:
    """Sends refused for longer than the bus timeout (no node acknowledging: a gimbal unplugged)
    disengage instead of ending the run; the adapter sending again re-engages."""
    bus = FlakyBus(channel=channel)
    with GimbalClient(bus) as gimbal:
        streamer = gimbal.speed_streamer(max_age=60.0, bus_timeout=0.6)
        streamer.set(3, 3)
        peer.wait_for(SpeedControl, where=lambda m: m.yaw_speed == 30)
        bus.fail_send = True
        poll(lambda: streamer.stats["disengaged"] == 1)
        streamer.set(1, 0)  # no error: the run goes on
        bus.fail_send = False
        poll(lambda: streamer.stats["reengaged"] == 1)
        peer.wait_for(SpeedControl, where=lambda m: m.yaw_speed == 10 and m.ctrl_byte == ZERO[3])
        assert streamer.error is None and streamer.stats["send_errors"] >= 10
    assert speed_messages(peer)[-2:] == [ZERO, RELEASE]
    bus.shutdown()


def test_a_lost_receive_side_halts_the_streamer_and_stops_the_gimbal(channel: str,
                                                                      peer: ScriptedPeer) -> None:
    bus = FlakyBus(channel=channel)
    with GimbalClient(bus) as gimbal:
        streamer = gimbal.speed_streamer()
        streamer.set(3, 3)
        peer.wait_for(SpeedControl, where=lambda m: m.yaw_speed == 30)
        bus.fail_recv = True
        poll(lambda: streamer.error is not None)
        with pytest.raises(BusError):
            streamer.set(1, 0)
        poll(lambda: speed_messages(peer)[-2:] == [ZERO, RELEASE])
        time.sleep(0.1)  # nothing moves the gimbal after the stop
        assert speed_messages(peer)[-2:] == [ZERO, RELEASE]
    bus.shutdown()


def test_an_unexpected_failure_in_the_thread_stops_the_gimbal_and_is_raised(
        client: GimbalClient, peer: ScriptedPeer, monkeypatch: pytest.MonkeyPatch) -> None:
    streamer = client.speed_streamer()
    streamer.set(5, 5)
    peer.wait_for(SpeedControl, where=lambda m: m.yaw_speed == 50)

    def broken() -> None:
        raise RuntimeError("a bug in the keep-alive")

    monkeypatch.setattr(streamer, "_tick", broken)
    streamer.set(6, 6)  # wakes the thread, which fails on its next send
    peer.wait_for(SpeedControl, where=lambda m: m.ctrl_byte == RELEASE[3])
    assert speed_messages(peer)[-2:] == [ZERO, RELEASE]
    assert isinstance(streamer.error, RuntimeError) and not streamer.running
    with pytest.raises(BusError, match="a bug in the keep-alive"):
        streamer.set(1, 1)


def test_a_stop_repeated_after_an_interrupted_one_waits_for_the_last_send(
        client: GimbalClient, peer: ScriptedPeer, monkeypatch: pytest.MonkeyPatch) -> None:
    """Ctrl-C during stop()'s join while the thread is in a (slow) send: the repeated stop() must
    wait for that send, so that the client's stop that follows is the last word on the bus."""
    import threading

    streamer = client.speed_streamer(max_age=60.0)
    streamer.set(5, 5)
    peer.wait_for(SpeedControl, where=lambda m: m.yaw_speed == 50)
    real_tick, in_tick = streamer._tick, threading.Event()

    def slow_tick():  # type: ignore[no-untyped-def]
        in_tick.set()
        time.sleep(0.3)
        return real_tick()

    monkeypatch.setattr(streamer, "_tick", slow_tick)
    streamer.set(6, 6)
    assert in_tick.wait(5.0)
    thread = streamer._thread
    real_join = thread.join

    def interrupted_join(timeout: float | None = None) -> None:
        monkeypatch.setattr(thread, "join", real_join)
        raise KeyboardInterrupt

    monkeypatch.setattr(thread, "join", interrupted_join)
    with pytest.raises(KeyboardInterrupt):
        streamer.stop()
    streamer.stop()
    client.safety_stop()  # what the client's close() does next
    time.sleep(0.5)  # a send still under way would land by now
    assert speed_messages(peer)[-3:] == [(60, 0, 60, 0x88), ZERO, RELEASE]


@pytest.mark.parametrize("rate", [3.9, 51.0, float("inf"), float("nan")])
def test_rates_outside_4_to_50_hz_are_refused(client: GimbalClient, rate: float) -> None:
    with pytest.raises(ValueError, match="4 to 50 Hz"):
        SpeedStreamer(client, rate_hz=rate)


def test_every_count_is_in_the_stats_from_the_start(client: GimbalClient) -> None:
    """Counts that stayed 0 were missing, so summary.json lacked the keys docs/track.md lists."""
    streamer = client.speed_streamer()
    streamer.stop()
    assert set(STAT_KEYS) <= set(streamer.stats) and streamer.stats["reply_errors"] == 0
