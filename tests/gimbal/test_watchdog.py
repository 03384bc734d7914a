"""The bus watchdog alone, on a fake clock: states, counts and the snapshot's shape."""
from __future__ import annotations

import pytest

from gimbal.watchdog import DEGRADED, DISENGAGED, ENGAGED, BusWatchdog


class FakeClock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t

    def advance(self, dt: float) -> None:
        self.t += dt


def ticks(dog: BusWatchdog, clock: FakeClock, n: int, *, answered: bool, period: float = 0.04) -> None:
    """``n`` keep-alive commands, each answered in time or never."""
    for _ in range(n):
        clock.advance(period)
        if answered:
            dog.replied()
        else:
            dog.timed_out()
            dog.unanswered()


@pytest.fixture
def clock() -> FakeClock:
    return FakeClock()


def test_a_clean_link_stays_engaged(clock: FakeClock) -> None:
    dog = BusWatchdog(clock=clock)
    ticks(dog, clock, 200, answered=True)
    health = dog.snapshot()
    assert health.state == ENGAGED and health.clean
    assert (health.unanswered, health.episodes, health.unreachable_s) == (0, 0, 0.0)


def test_one_lost_reply_is_not_an_episode_but_two_are(clock: FakeClock) -> None:
    dog = BusWatchdog(clock=clock)
    ticks(dog, clock, 1, answered=False)
    ticks(dog, clock, 1, answered=True)
    assert dog.poll() == ENGAGED
    ticks(dog, clock, 1, answered=False)
    assert dog.poll() == DEGRADED
    assert dog.snapshot().episodes == 1


def test_degraded_until_a_whole_window_is_answered(clock: FakeClock) -> None:
    dog = BusWatchdog(clock=clock, window=25)
    ticks(dog, clock, 3, answered=False)
    assert dog.poll() == DEGRADED
    ticks(dog, clock, 24, answered=True)
    assert dog.poll() == DEGRADED
    ticks(dog, clock, 1, answered=True)
    assert dog.poll() == ENGAGED


def test_a_short_silence_is_one_episode_though_its_commands_are_judged_later(clock: FakeClock) -> None:
    """0.56 s without replies degrades at once; the commands of that silence are given up only
    0.5 s after they were sent, by when the replies are back: still the same episode."""
    dog = BusWatchdog(clock=clock)
    ticks(dog, clock, 25, answered=True)
    for _ in range(14):  # 0.56 s: timed out, not yet given up
        clock.advance(0.04)
        dog.timed_out()
    assert dog.poll() == DEGRADED
    ticks(dog, clock, 5, answered=True)  # replies again; the silent ones not judged yet
    for _ in range(14):
        dog.unanswered()
    ticks(dog, clock, 40, answered=True)
    assert dog.poll() == ENGAGED
    assert dog.snapshot().episodes == 1


def waiting(dog: BusWatchdog, clock: FakeClock, seconds: float, period: float = 0.04) -> None:
    """Commands timing out, none answered yet, for ``seconds``."""
    for _ in range(round(seconds / period)):
        clock.advance(period)
        dog.timed_out()


def test_a_wait_of_half_a_second_degrades_at_once_and_counts_as_unreachable(clock: FakeClock) -> None:
    dog = BusWatchdog(clock=clock)
    ticks(dog, clock, 10, answered=True)
    waiting(dog, clock, 0.48)
    assert dog.poll() == ENGAGED  # 0.44 s since the first command went unanswered
    waiting(dog, clock, 0.08)
    assert dog.poll() == DEGRADED
    dog.replied(late=True)
    health = dog.snapshot()
    assert health.unreachable_s == pytest.approx(0.52)
    assert health.disengagements == 0


def test_a_keep_alive_that_stalls_is_no_silent_gimbal(clock: FakeClock) -> None:
    """Under load the keep-alive's own thread may not run for a while: nothing sent, nothing missing."""
    dog = BusWatchdog(clock=clock)
    ticks(dog, clock, 10, answered=True)
    clock.advance(5.0)
    health = dog.snapshot()
    assert (health.state, health.episodes, health.unreachable_s) == (ENGAGED, 0, 0.0)


def test_silence_of_the_timeout_disengages_and_a_reply_reengages(clock: FakeClock) -> None:
    dog = BusWatchdog(2.0, clock=clock)
    ticks(dog, clock, 5, answered=True)
    ticks(dog, clock, 1, answered=False)
    first_miss = clock.t
    ticks(dog, clock, 49, answered=False)  # 1.96 s after the first miss
    assert dog.poll() == DEGRADED
    clock.advance(0.04)
    assert dog.poll() == DISENGAGED
    assert dog.snapshot().since == pytest.approx(first_miss + 2.0)
    clock.advance(3.0)
    assert dog.snapshot().unreachable_s == pytest.approx(5.0)  # the ongoing silence is included
    dog.replied()
    health = dog.snapshot()
    assert health.state == DEGRADED  # in control again; engaged once a window is answered
    assert (health.episodes, health.disengagements) == (1, 1)
    assert health.unreachable_s == pytest.approx(5.0)
    ticks(dog, clock, 25, answered=True)
    assert dog.poll() == ENGAGED


def test_late_replies_and_nacks_show_the_gimbal_hears(clock: FakeClock) -> None:
    """A 150 ms reply delay: every command times out and is answered late; not a bad link."""
    dog = BusWatchdog(clock=clock)
    for _ in range(100):
        clock.advance(0.04)
        dog.timed_out()
        dog.replied(late=True)
    dog.replied(nack=True)
    health = dog.snapshot()
    assert health.state == ENGAGED
    assert (health.timeouts, health.late, health.nacks, health.unanswered) == (100, 100, 1, 0)


def test_the_snapshot_is_plain_data(clock: FakeClock) -> None:
    health = BusWatchdog(clock=clock).snapshot()
    assert set(health.as_dict()) == {"state", "since", "unanswered", "late", "timeouts", "nacks",
                                     "unreachable_s", "episodes", "disengagements"}
    with pytest.raises(AttributeError):
        health.state = DEGRADED  # type: ignore[misc]


def test_a_timeout_at_or_below_the_degraded_silence_is_refused() -> None:
    with pytest.raises(ValueError, match="bus timeout"):
        BusWatchdog(0.5)


def test_once_closed_the_silence_after_the_last_command_is_not_judged(clock: FakeClock) -> None:
    """The track summary is written after the stop, video and plot: seconds without commands
    once read as a silent gimbal released (unreachable 5.1 s on a clean demo run)."""
    dog = BusWatchdog(clock=clock)
    ticks(dog, clock, 25, answered=True)
    dog.close()
    clock.advance(10.0)
    health = dog.snapshot()
    assert (health.state, health.episodes, health.unreachable_s) == (ENGAGED, 0, 0.0)
