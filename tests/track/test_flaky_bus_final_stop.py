"""Issue #26 item 4, end to end: a SIGTERM to ``track --realtime`` driving a ``gimbaltrack sim
--corrupt 0.1`` in another process (udp_multicast). The final stop, zero speed then release, is
resent (same SEQ) until the gimbal answers or 0.5 s have passed, as the CAN log shows, and the
gimbal is still within 0.6 s. A gimbal that answers nothing at that moment (the simulator's
process frozen) makes the resends certain: the zero for a quarter second, the release up to 0.5 s."""
from __future__ import annotations

import json
import signal
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from gimbal.log_decode import GIMBAL_TO_HOST
from gimbal.messages.motion import SPEED_HOLD, SPEED_RELEASE
from gimbal.session import STOP_RESEND_S, STOP_RETRY_S
from tests.support import cli_command, free_udp_port, subprocess_env, wait_until
from tests.track.helpers import (
    DEMO,
    DEMO_ROI,
    decoded,
    host_commands,
    start,
    track_command,
)

GROUP = "239.74.163.26"
STOPPED_WITHIN_S = 0.6
SLACK_S = 0.1  # scheduling on a loaded machine: a resend a little late, a last one a little early


@dataclass
class FinalStop:
    """One of the two stop commands: every time it went out, and the gimbal's valid replies to it."""

    attempts: list[float]  # wall-clock send times (the CAN log's)
    replies: list[float]


def final_stop(records: list[dict[str, Any]]) -> tuple[FinalStop, FinalStop]:
    """The zero (in control) and the release of the run's final stop, found by the SEQ of the last
    speed command of each kind (resends keep the SEQ)."""
    speeds = [r for r in host_commands(records) if r["name"] == "speed_control"]
    assert speeds[-1]["fields"]["ctrl_byte"] == SPEED_RELEASE, "the last speed command is no release"

    def zero(r: dict[str, Any]) -> bool:
        f = r["fields"]
        return f["yaw_speed"] == f["roll_speed"] == f["pitch_speed"] == 0

    last_zero = next(r for r in reversed(speeds) if zero(r) and r["fields"]["ctrl_byte"] == SPEED_HOLD)
    stops = []
    for seq, ctrl in ((last_zero["seq"], SPEED_HOLD), (speeds[-1]["seq"], SPEED_RELEASE)):
        sent = [r for r in speeds if r["seq"] == seq]
        assert all(zero(r) and r["fields"]["ctrl_byte"] == ctrl for r in sent)
        replies = [r["timestamp"] for r in records if r["direction"] == GIMBAL_TO_HOST and "error" not in r
                   and r.get("is_reply") and r["seq"] == seq]
        stops.append(FinalStop([r["timestamp"] for r in sent], replies))
    return stops[0], stops[1]


def assert_resent_until_answered(stop: FinalStop, until: float) -> None:
    """Resent every ``STOP_RESEND_S`` while unanswered, never again once answered (one resend may
    cross the reply on the bus), and, if never answered, up to ``until``."""
    gaps = [b - a for a, b in zip(stop.attempts, stop.attempts[1:])]
    assert all(gap <= STOP_RESEND_S + SLACK_S for gap in gaps), gaps
    if stop.replies:
        assert len([t for t in stop.attempts if t > stop.replies[0]]) <= 1, (stop.attempts, stop.replies)
    else:
        assert stop.attempts[-1] >= until - STOP_RESEND_S - SLACK_S, (stop.attempts, until)


@dataclass
class Run:
    code: int
    stderr: str
    out: Path
    sim_states: list[dict[str, Any]]  # the simulator's status lines after the run (time: its monotonic clock)
    wall_minus_monotonic: float


def run_and_terminate(tmp_path: Path, freeze_gimbal: bool) -> Run:
    """Start the simulator with ``--corrupt 0.1`` and ``track --realtime`` against it; SIGTERM the
    run once it is tracking (with ``freeze_gimbal``, SIGSTOP the simulator first and SIGCONT it
    once the run has ended, so that it hears the stop only late)."""
    env = subprocess_env(free_udp_port())
    sim = start(cli_command("sim", "-i", "udp_multicast", "-c", GROUP, "--corrupt", "0.1", "--seed", "26",
                            "--status-interval", "0.05", "--json"), env)
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.extend(sim.stdout), daemon=True)  # type: ignore[arg-type]
    reader.start()
    out = tmp_path / "out"
    try:
        assert wait_until(lambda: lines, 30, step=0.05), "the simulator did not start"
        track = start(track_command(DEMO, out, "--roi", DEMO_ROI, "--realtime", "--no-video",
                                    "-i", "udp_multicast", "-c", GROUP), env)
        telemetry = out / "telemetry.jsonl"
        assert wait_until(lambda: telemetry.exists() and len(telemetry.read_text().splitlines()) > 40, 30,
                          step=0.05), "the run did not start tracking"
        if freeze_gimbal:
            sim.send_signal(signal.SIGSTOP)
        track.send_signal(signal.SIGTERM)
        try:
            _, stderr = track.communicate(timeout=20)
        finally:
            if freeze_gimbal:
                sim.send_signal(signal.SIGCONT)
        time.sleep(1.0)  # the simulator hears what it missed, decelerates and reports every 0.05 s
    finally:
        sim.send_signal(signal.SIGTERM)
        sim.wait(timeout=10)
        reader.join(timeout=10)
    return Run(track.returncode, stderr, out, [json.loads(line) for line in lines],
               time.time() - time.monotonic())


@pytest.fixture(scope="module")
def corrupt(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Run]:
    yield run_and_terminate(tmp_path_factory.mktemp("corrupt"), freeze_gimbal=False)


def test_sigterm_under_a_corrupting_bus_ends_the_run_with_its_outputs(corrupt: Run) -> None:
    assert corrupt.code == 128 + signal.SIGTERM, corrupt.stderr
    assert "Traceback" not in corrupt.stderr
    assert json.loads((corrupt.out / "summary.json").read_text())["status"] == "terminated (SIGTERM)"


def test_the_final_stop_is_resent_until_answered_within_half_a_second(corrupt: Run) -> None:
    zero, release = final_stop(decoded(corrupt.out / "can.log"))
    began = zero.attempts[0]
    assert_resent_until_answered(zero, began + STOP_RETRY_S / 2)
    assert_resent_until_answered(release, began + STOP_RETRY_S)
    assert zero.attempts[-1] < release.attempts[0] <= release.attempts[-1] <= began + STOP_RETRY_S + SLACK_S


def test_the_gimbal_stands_still_within_0_6_s_of_the_final_stop(corrupt: Run) -> None:
    zero, release = final_stop(decoded(corrupt.out / "can.log"))
    stop_at = zero.attempts[0] - corrupt.wall_minus_monotonic  # on the simulator's clock
    after = [s for s in corrupt.sim_states if s["time"] >= stop_at + STOPPED_WITHIN_S]
    assert after, "no simulator status after the stop"
    assert all(s["speeds"] == [0.0, 0.0, 0.0] and not s["moving"] for s in after), after[0]
    if release.replies:  # the gimbal confirmed the release
        assert not after[-1]["speed_control"]


def test_a_gimbal_answering_nothing_gets_the_stop_resent_for_half_a_second(tmp_path: Path) -> None:
    run = run_and_terminate(tmp_path, freeze_gimbal=True)
    assert run.code == 128 + signal.SIGTERM and "Traceback" not in run.stderr, run.stderr
    zero, release = final_stop(decoded(run.out / "can.log"))
    assert not zero.replies and not release.replies
    began = zero.attempts[0]
    expected = round(STOP_RETRY_S / 2 / STOP_RESEND_S)  # sends of each in its quarter second
    assert len(zero.attempts) >= expected - 2 and len(release.attempts) >= expected - 2, (zero, release)
    assert_resent_until_answered(zero, began + STOP_RETRY_S / 2)
    assert_resent_until_answered(release, began + STOP_RETRY_S)
    assert zero.attempts[-1] < release.attempts[0] <= release.attempts[-1] <= began + STOP_RETRY_S + SLACK_S
    final = run.sim_states[-1]  # thawed, it heard the zero and the release
    assert final["speeds"] == [0.0, 0.0, 0.0] and not final["moving"] and not final["speed_control"]


def test_the_resend_checks_catch_a_stop_sent_once() -> None:
    """The check itself: one unanswered send is not a stop resent until its deadline."""
    with pytest.raises(AssertionError):
        assert_resent_until_answered(FinalStop([100.0], []), 100.0 + STOP_RETRY_S)
    with pytest.raises(AssertionError):
        assert_resent_until_answered(FinalStop([100.0, 100.05, 100.1], [100.01]), 100.5)
