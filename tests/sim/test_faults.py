"""Under each injected fault the client retries or fails clearly, and the gimbal ends at rest."""
from __future__ import annotations

import time

import pytest

from gimbal.errors import GimbalError, GimbalTimeoutError, ReturnCodeError
from gimbal.messages import message_packet, motion
from gimbal.messages.telemetry import PUSH_ENABLE, ParameterPush, PushControl
from gimbal.packet import encode_packet
from gimbal.sim import Faults
from tests.sim.helpers import wait_until


def run_requests(client, count: int) -> tuple[int, list[GimbalError]]:  # type: ignore[no-untyped-def]
    """``count`` angle reads: how many succeeded, and the errors of the others."""
    ok, errors = 0, []
    for _ in range(count):
        try:
            client.get_angles("joint")
            ok += 1
        except GimbalError as exc:
            errors.append(exc)
    return ok, errors


@pytest.mark.parametrize("faults, counter", [
    (Faults(drop=0.1, direction="rx", seed=1), "dropped_rx"),
    (Faults(drop=0.1, direction="tx", seed=2), "dropped_tx"),
    (Faults(corrupt=0.1, seed=3), "corrupted_rx"),
])
def test_lossy_bus_costs_retries_not_answers(make_client, faults: Faults, counter: str) -> None:
    client, sim = make_client(faults=faults, timeout=0.03, retries=4)
    ok, errors = run_requests(client, 30)
    assert ok >= 27 and all(isinstance(e, GimbalTimeoutError) for e in errors)
    assert client.stats["retries"] > 0 and sim.state().faults[counter] > 0


def test_delayed_replies_are_caught_by_a_retry_or_time_out_clearly(make_client) -> None:
    client, sim = make_client(faults=Faults(delay_s=0.15), timeout=0.1, retries=2)
    assert run_requests(client, 2) == (2, [])
    assert client.stats["retries"] >= 2
    slow, _ = make_client(faults=Faults(delay_s=0.5), timeout=0.05, retries=1)
    with pytest.raises(GimbalTimeoutError, match=r"no reply within 50 ms \(2 attempts\)"):
        slow.get_angles()


def test_nack_refuses_without_executing(make_client) -> None:
    client, sim = make_client(faults=Faults(nack=1.0, nack_code=0xFF))
    with pytest.raises(ReturnCodeError, match="0xFF") as err:
        client.position(30.0, 0.0, 0.0, time_s=0.1)
    assert err.value.return_code == 0xFF
    time.sleep(0.15)
    state = sim.state()
    assert state.joint == (0.0, 0.0, 0.0) and state.faults["nacks"] == 1
    half, half_sim = make_client(faults=Faults(nack=0.5, seed=4))
    refused = sum(1 for e in run_requests(half, 20)[1] if isinstance(e, ReturnCodeError))
    assert 4 <= refused <= 16 and half_sim.state().faults["nacks"] == refused


def test_silent_window_times_out_then_recovers(make_client) -> None:
    client, sim = make_client(faults=Faults(silent=(0.0, 0.4)), timeout=0.05, retries=0)
    with pytest.raises(GimbalTimeoutError):
        client.get_angles()
    time.sleep(0.4)
    assert client.get_angles("joint").yaw == 0.0
    assert sim.state().faults["silent_rx"] > 0


def test_mixed_legacy_replies_and_foreign_traffic(make_client) -> None:
    client, sim = make_client(faults=Faults(legacy=0.5, foreign_rate=2000.0, seed=5))
    start = time.monotonic()
    assert run_requests(client, 20) == (20, [])
    time.sleep(max(0.0, 0.3 - (time.monotonic() - start)))
    faults = sim.state().faults
    assert faults["legacy_replies"] > 3
    assert faults["foreign_sent"] >= 0.5 * 2000 * (time.monotonic() - start)


@pytest.mark.parametrize("faults", [Faults(drop=0.2, seed=6), Faults(delay_s=0.08), Faults(nack=0.5, seed=7),
                                    Faults(silent=(0.35, 2.0))], ids=["drop", "delay", "nack", "silent"])
def test_gimbal_at_rest_after_the_client_stops(make_client, faults: Faults) -> None:
    client, sim = make_client(faults=faults, timeout=0.1, retries=1)
    streamer = client.speed_streamer(rate_hz=25.0)
    streamer.set(30.0, -10.0)
    assert wait_until(lambda: sim.state().moving, 0.5)
    time.sleep(0.3)
    stopped_at = time.monotonic()
    client.close()
    assert wait_until(lambda: not sim.state().moving, 0.7)
    time.sleep(0.1)
    assert not sim.state().moving and time.monotonic() - stopped_at < 1.5


def test_a_command_after_one_that_lost_its_final_frame_is_still_answered(sim_host) -> None:
    """The simulator once fed frames to its framer as a byte stream: a lost one-byte final frame
    (0xAA) let the broken packet pass its CRC with the next packet's first byte, losing that one."""
    host, _ = sim_host
    stop = motion.SpeedControl()
    broken = next(raw for seq in range(0x10000)
                  if (raw := encode_packet(message_packet(stop, seq)))[-1] == 0xAA and len(raw) % 8 == 1)
    host.transport.send(broken[:-1])  # every frame but the last, one-byte one
    assert isinstance(host.ask(motion.GetAngles()), motion.AnglesReply)


def test_the_same_seed_loses_the_same_replies_whatever_the_pushes_draw(make_client) -> None:
    """The pushes (tick thread) once drew from the replies' RNG, so a seed did not repeat a run."""
    def outcomes() -> str:
        client, _ = make_client(faults=Faults(drop=0.2, direction="tx", seed=7), timeout=0.25, retries=0)
        client.request(PushControl(PUSH_ENABLE), retries=20)
        marks = ""
        for _ in range(20):
            try:
                client.get_angles()
                marks += "."
            except GimbalTimeoutError:
                marks += "x"
        return marks

    first = outcomes()
    assert "x" in first and "." in first and outcomes() == first


def test_a_delay_beyond_what_a_thread_can_wait_keeps_the_simulator_running(make_client) -> None:
    """``sim --delay-ms 1e300`` passes the finite-number check; the tick thread's wait until that
    reply was due overflowed (OverflowError traceback) and it died: no pushes from then on."""
    client, sim = make_client(faults=Faults(delay_s=1e297), timeout=0.1, retries=0)
    with pytest.raises(GimbalTimeoutError):
        client.version()  # its reply queued for 1e297 s, nothing else due
    with pytest.raises(GimbalTimeoutError):
        client.set_push(True)  # executed at once, its reply queued too
    client.wait_for_push(ParameterPush, 2.0)


@pytest.mark.parametrize("rate", [-1.0, 20_001.0, 1e300])
def test_foreign_traffic_is_bounded_by_what_a_bus_carries(rate: float) -> None:
    """1e300 frames/s was taken, and the tick thread then built that many frames at once."""
    with pytest.raises(ValueError, match="foreign_rate"):
        Faults(foreign_rate=rate)
