"""How well the gimbal answers, as a state machine with no I/O: fed each speed command's outcome
by the keep-alive, read by the loop, the console and ``gimbaltrack doctor``.

States: ``engaged`` (replies come back), ``degraded`` (replies missing: the keep-alive goes on
streaming, the run goes on tracking; for ``MIN_DEGRADED_S`` at least, so that the commands of a
short silence, judged unanswered only later, do not make a second episode), ``disengaged`` (nothing heard for ``timeout_s``: the
keep-alive sends zero and releases control, then only probes), and back to ``degraded`` (then
``engaged``) as soon as the gimbal answers again. A late reply, a NACK and a reply in time all
show that the gimbal hears us; only a command never answered counts against the link.
"""
from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

ENGAGED = "engaged"
DEGRADED = "degraded"
DISENGAGED = "disengaged"
STATES = (ENGAGED, DEGRADED, DISENGAGED)

DEFAULT_TIMEOUT_S = 3.0  # silence before the gimbal is released (--bus-timeout)
DEGRADED_SILENCE_S = 0.5  # a command waiting this long for a reply: degraded (one command's validity)
UNREACHABLE_AFTER_S = 0.2  # a wait this long counts in ``unreachable_s``
WINDOW = 25  # the latest outcomes judged (1 s of the keep-alive at 25 Hz)
DEGRADED_MISSES = 2  # unanswered commands among them that make the link degraded
MIN_DEGRADED_S = 1.0  # at least this long degraded: a command counts as unanswered only 0.5 s after it


@dataclass(frozen=True)
class BusHealth:
    """A read-only view of the link. ``since``: when the current state began (the watchdog's clock,
    ``time.monotonic()`` by default); ``unanswered``: speed commands never answered; ``late``:
    answered after their window; ``timeouts``: not answered within their window (late or never);
    ``nacks``: refused by the gimbal; ``unreachable_s``: time commands waited for a reply in
    stretches of ``UNREACHABLE_AFTER_S`` or more, the current one included; ``episodes``: times the link left
    ``engaged``; ``disengagements``: times the gimbal was released for silence."""

    state: str
    since: float
    unanswered: int
    late: int
    timeouts: int
    nacks: int
    unreachable_s: float
    episodes: int
    disengagements: int

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)

    @property
    def clean(self) -> bool:
        """Whether the link never left ``engaged``."""
        return self.episodes == 0


class BusWatchdog:
    """The link's state from reply outcomes. Thread-safe: the keep-alive feeds it, others read it.
    ``clock`` is the monotonic clock of every event (a test passes a fake one)."""

    def __init__(self, timeout_s: float = DEFAULT_TIMEOUT_S, *, degraded_silence_s: float = DEGRADED_SILENCE_S,
                 window: int = WINDOW, degraded_misses: int = DEGRADED_MISSES,
                 clock: Callable[[], float] = time.monotonic) -> None:
        if not 0 < degraded_silence_s < timeout_s:
            raise ValueError(f"the bus timeout must be above {degraded_silence_s:g} s, not {timeout_s!r}")
        if not 1 <= degraded_misses <= window:
            raise ValueError("degraded_misses must be 1 to window")
        self.timeout_s = timeout_s
        self.degraded_silence_s = degraded_silence_s
        self.degraded_misses = degraded_misses
        self._clock = clock
        self._lock = threading.Lock()
        now = clock()
        self._state = ENGAGED
        self._since = now
        self._waiting_since: float | None = None  # the first command not answered in time since the last reply
        self._outcomes: deque[bool] = deque(maxlen=window)  # True: heard, False: never answered
        self._counts = dict.fromkeys(("unanswered", "late", "timeouts", "nacks", "episodes", "disengagements"), 0)
        self._unreachable_s = 0.0
        self._silence_counted = False  # the current silence is long enough to count as unreachable
        self._closed_at: float | None = None

    # -- events (the keep-alive's thread) --------------------------------------------------
    def replied(self, *, late: bool = False, nack: bool = False) -> None:
        """The gimbal answered a command (``late``: after its window; ``nack``: refused it)."""
        with self._lock:
            now = self._now()
            if late:
                self._counts["late"] += 1
            if nack:
                self._counts["nacks"] += 1
            self._end_silence(now)
            self._outcomes.append(True)
            self._judge(now)

    def timed_out(self) -> None:
        """A command was not answered within its window (it may still be, late)."""
        with self._lock:
            self._counts["timeouts"] += 1
            self._wait(self._now())

    def unanswered(self) -> None:
        """A command was given up for good: no reply, not even late."""
        with self._lock:
            self._counts["unanswered"] += 1
            self._outcomes.append(False)
            self._wait(self._now())

    def close(self) -> None:
        """No more commands (streaming stopped): the state and figures stay as they are now,
        since a silence after the last command says nothing about the link."""
        with self._lock:
            self._judge(self._clock())
            if self._closed_at is None:
                self._closed_at = self._clock()

    # -- reading -------------------------------------------------------------------------
    def _now(self) -> float:
        return self._clock() if self._closed_at is None else self._closed_at

    def poll(self) -> str:
        """The state now (silence is judged against the clock)."""
        with self._lock:
            self._judge(self._now())
            return self._state

    def snapshot(self) -> BusHealth:
        with self._lock:
            now = self._now()
            self._judge(now)
            ongoing = now - self._waiting_since if self._silence_counted and self._waiting_since is not None else 0.0
            return BusHealth(self._state, self._since, unreachable_s=self._unreachable_s + ongoing,
                             **self._counts)

    # -- the machine (lock held) ------------------------------------------------------------
    def _wait(self, now: float) -> None:
        """A command without its reply: the silence runs from the first one (a keep-alive that
        itself stalled, sending nothing, is not a silent gimbal)."""
        if self._waiting_since is None:
            self._waiting_since = now
        self._judge(now)

    def _end_silence(self, now: float) -> None:
        if self._silence_counted and self._waiting_since is not None:
            self._unreachable_s += now - self._waiting_since
        self._silence_counted = False
        self._waiting_since = None
        if self._state == DISENGAGED:  # the gimbal answers again: take control back, still degraded
            self._enter(DEGRADED, now)

    def _judge(self, now: float) -> None:
        silence = 0.0 if self._waiting_since is None else now - self._waiting_since
        if silence >= UNREACHABLE_AFTER_S:
            self._silence_counted = True
        if silence >= self.timeout_s:
            if self._state != DISENGAGED:
                self._counts["disengagements"] += 1
                self._enter(DISENGAGED, now)
            return
        if self._state == DISENGAGED:
            return  # only a reply ends it
        misses = self._outcomes.count(False)
        bad = silence >= self.degraded_silence_s or misses >= self.degraded_misses
        if bad and self._state == ENGAGED:
            self._enter(DEGRADED, now)
        elif self._state == DEGRADED and not bad and misses == 0 and now - self._since >= MIN_DEGRADED_S:
            self._enter(ENGAGED, now)

    def _enter(self, state: str, now: float) -> None:
        if self._state == ENGAGED:
            self._counts["episodes"] += 1
        self._state, self._since = state, now
