"""The speed keep-alive: one speed command lasts 0.5 s on the gimbal, so the latest setpoint is
resent at a fixed rate from a background thread.

Replies are not waited for synchronously: each send is a reply-required speed command whose
reply is checked at the next send (at least half a period later, 20 ms at 25 Hz, against replies
that arrive within ~5 ms), so a slow or silent gimbal never lowers the send rate. A new setpoint
is sent at once (if half a period has passed since the last send) instead of waiting for the
next tick, which keeps the capture-to-command latency low; the schedule restarts from there.

Each command's outcome feeds a ``gimbal.watchdog.BusWatchdog``: a reply in time, a late one (the
gimbal hears us, slowly), or none within the time one command lasts (unanswered). Missing replies
never end streaming: after the watchdog's timeout of silence the gimbal is stopped and released
(``disengaged``), then probed with a release a few times a second; its first answer re-engages
it, and the latest setpoint streams again.
"""
from __future__ import annotations

import logging
import math
import threading
import time
from collections import Counter, deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import can

from gimbal.errors import BusError, GimbalError, SendError
from gimbal.messages import Message, Reply
from gimbal.messages.limits import MAX_SPEED_DPS, SPEED_COMMAND_LASTS_S
from gimbal.messages.motion import SPEED_HOLD, SPEED_RELEASE, SpeedControl, finite_number, to_raw
from gimbal.watchdog import DISENGAGED, BusWatchdog

if TYPE_CHECKING:
    from gimbal.matcher import PendingReply

log = logging.getLogger(__name__)

DEFAULT_MAX_AGE_S = 0.3  # a setpoint this old is replaced by zero speed
STAT_KEYS = ("sent", "zero_sent", "replies", "late_replies", "reply_errors", "reply_timeouts",
             "send_errors", "unanswered", "disengaged", "reengaged", "probes")  # from the start
PROBE_EVERY_S = 0.2  # while disengaged: a release, to learn when the gimbal answers again
MIN_RATE_HZ = 2 / SPEED_COMMAND_LASTS_S  # at least two sends inside the time one command lasts
MAX_RATE_HZ = 50.0  # public drivers use 10-50 Hz; a new setpoint may go out at twice the rate, and
# each reply (a few ms) must be back by the next send, half a period later at the least


class SpeedSender(Protocol):
    """What the keep-alive needs from a client: send a command without waiting, collect or drop
    its reply, and the safety stop."""

    def submit(self, message: Message) -> PendingReply: ...

    def cancel(self, waiter: PendingReply) -> None: ...

    def result(self, waiter: PendingReply) -> Reply: ...

    def stop_and_release(self) -> None: ...


@dataclass
class _Setpoint:
    yaw: int  # 0.1 °/s
    roll: int
    pitch: int
    set_at: float
    stamp: float
    sent: bool = False


def _clamped_raw(value: float, name: str) -> int:
    return to_raw(max(-MAX_SPEED_DPS, min(MAX_SPEED_DPS, finite_number(value, name))), name)


class SpeedStreamer:
    """Streams the latest yaw/pitch/roll speed setpoint at ``rate_hz``.

    A setpoint older than ``max_age`` seconds (since ``set()``, on ``clock``) is never resent:
    zero speed goes out instead, so a stalled tracker stops the gimbal. Reply errors, reply
    timeouts and sends the bus refused (a full transmit queue) are counted in ``stats``; so are
    replies that came after their command's window (``late_replies``: a slow link, e.g.
    ``gimbaltrack sim --delay-ms 150``), which show the gimbal hears us, and commands never
    answered (``unanswered``). ``watchdog`` (default: a ``BusWatchdog`` with its default timeout)
    judges the link from them; while it says ``disengaged`` no setpoint goes out (see the module's
    docstring). Only a lost bus (``halt``) or a failure of the thread ends streaming: ``error`` is
    set and the next ``set()`` raises ``BusError``.
    """

    def __init__(self, client: SpeedSender, rate_hz: float = 25.0, max_age: float = DEFAULT_MAX_AGE_S, *,
                 watchdog: BusWatchdog | None = None, clock: Callable[[], float] = time.monotonic) -> None:
        if not MIN_RATE_HZ <= rate_hz <= MAX_RATE_HZ:
            raise ValueError(f"the keep-alive rate must be {MIN_RATE_HZ:g} to {MAX_RATE_HZ:g} Hz (a command "
                             f"lasts 0.5 s; replies must be back by the next send), not {rate_hz:g}")
        if not max_age > 0:
            raise ValueError("max_age must be > 0")
        self.rate_hz = rate_hz
        self.max_age = max_age
        self.watchdog = watchdog if watchdog is not None else BusWatchdog()
        self.stats: Counter[str] = Counter(dict.fromkeys(STAT_KEYS, 0))
        self.error: BaseException | None = None
        self._client = client
        self._clock = clock
        self._lock = threading.Lock()
        self._setpoint: _Setpoint | None = None
        self._latencies: list[float] = []
        self._overdue: deque[tuple[float, PendingReply]] = deque()  # (sent at, waiter): timed out, may yet be answered
        self._engaged = True  # setpoints go out (False: disengaged, probing)
        self._last_probe = -math.inf
        self._halt = threading.Event()
        self._wake = threading.Event()  # a new setpoint: send it now rather than at the next tick
        self._stopped = False
        self._thread = threading.Thread(target=self._run, name="gimbal-speed", daemon=True)
        self._thread.start()

    @property
    def running(self) -> bool:
        return self._thread.is_alive() and not self._halt.is_set()

    def set(self, yaw_dps: float, pitch_dps: float, roll_dps: float = 0.0,
            stamp: float | None = None) -> None:
        """New setpoint in °/s, clamped to ±360. ``stamp`` is the capture time of the frame it
        came from (same clock; default now), for ``latencies()``. Speeds and stamp may be any real
        numbers (numpy's too); anything else, or one not finite, is a ``RangeError``."""
        if self.error is not None:
            raise BusError(f"speed streaming stopped: {self.error}") from self.error
        if self._stopped:
            raise GimbalError("the speed streamer is stopped")
        now = self._clock()
        setpoint = _Setpoint(_clamped_raw(yaw_dps, "yaw_dps"), _clamped_raw(roll_dps, "roll_dps"),
                             _clamped_raw(pitch_dps, "pitch_dps"), now,
                             now if stamp is None else finite_number(stamp, "stamp"))
        with self._lock:
            self._setpoint = setpoint
        self._wake.set()

    def latencies(self) -> list[float]:
        """Seconds from each setpoint's ``stamp`` to its first send on the bus."""
        with self._lock:
            return list(self._latencies)

    def stop(self) -> None:
        """Stop streaming, then send zero speed and release control (bit 7 clear). Idempotent, and
        every call returns only after the thread's last send, so a call repeated after an
        interrupted one (Ctrl-C during the join) never lets a setpoint follow the stop."""
        first = not self._stopped
        self._stopped = True
        self._halt.set()
        self._wake.set()
        if self._thread is not threading.current_thread():
            self._thread.join()
        self.watchdog.close()
        if first:
            self._client.stop_and_release()

    def halt(self, error: BaseException) -> None:
        """Stop streaming because the bus is lost (called by the client before its best-effort
        stop): returns once the thread has finished its current send, so nothing follows the stop."""
        self.error = self.error or error
        self._halt.set()
        self._wake.set()
        if self._thread is not threading.current_thread():
            self._thread.join(timeout=2.0)
        self.watchdog.close()

    def _run(self) -> None:
        period = 1.0 / self.rate_hz
        min_gap = period / 2
        pending: PendingReply | None = None
        next_tick = last_send = time.monotonic() - period
        try:
            while not self._halt.is_set():
                now = time.monotonic()
                early = self._wake.is_set() and now - last_send >= min_gap
                if now >= next_tick or early:
                    self._wake.clear()
                    self._collect(pending)
                    pending = self._tick()
                    last_send = now
                    behind = next_tick + period <= now  # fell behind: do not burst to catch up
                    next_tick = now + period if early or behind else next_tick + period
                elif self._wake.is_set():  # a new setpoint, but too soon after the last send
                    self._halt.wait(last_send + min_gap - now)
                else:
                    self._wake.wait(next_tick - now)
        except Exception as exc:  # the bus's errors, and any other: never end without a word
            if self._halt.is_set() and isinstance(exc, (GimbalError, can.CanError)):
                return  # stop() or halt() raced with a send: nothing is lost
            self.error = exc
            self._halt.set()
            log.warning("speed streaming stopped: %s", exc)  # the next set() raises it
            self._client.stop_and_release()
        finally:
            if pending is not None:
                self._client.cancel(pending)

    def _tick(self) -> PendingReply | None:
        if self.watchdog.poll() == DISENGAGED:
            return self._disengaged()
        if not self._engaged:
            self._engaged = True
            self.stats["reengaged"] += 1
            log.warning("the gimbal answers again: taking speed control back")
        now = self._clock()
        with self._lock:
            setpoint = self._setpoint
            fresh = setpoint is not None and now - setpoint.set_at <= self.max_age
        if fresh:
            assert setpoint is not None
            message = SpeedControl(setpoint.yaw, setpoint.roll, setpoint.pitch, SPEED_HOLD)
        else:
            message = SpeedControl(0, 0, 0, SPEED_HOLD)
        pending = self._submit(message)
        if pending is None:
            return None
        self.stats["sent"] += 1
        if not fresh:
            self.stats["zero_sent"] += 1
        elif not setpoint.sent:
            setpoint.sent = True
            with self._lock:
                self._latencies.append(self._clock() - setpoint.stamp)
        return pending

    def _submit(self, message: SpeedControl) -> PendingReply | None:
        """Send ``message``; a send the bus refuses (often passing: a full transmit queue, or no
        node acknowledging a frame) is counted as a command never answered."""
        try:
            return self._client.submit(message)
        except SendError as exc:
            self.stats["send_errors"] += 1
            self.stats["unanswered"] += 1
            log.debug("speed command not sent: %s", exc)
            self.watchdog.timed_out()
            self.watchdog.unanswered()
            return None

    def _disengaged(self) -> PendingReply | None:
        """Silence for the watchdog's timeout: stop and release the gimbal once, then probe it
        with a release every ``PROBE_EVERY_S`` until it answers."""
        if self._engaged:
            self._engaged = False
            self.stats["disengaged"] += 1
            log.warning("the gimbal has not answered for %.1f s: stopping and releasing it until it answers",
                        self.watchdog.timeout_s)
            self._client.stop_and_release()
        now = time.monotonic()
        if now - self._last_probe < PROBE_EVERY_S:
            return None
        self._last_probe = now
        pending = self._submit(SpeedControl(0, 0, 0, SPEED_RELEASE))
        if pending is not None:
            self.stats["probes"] += 1
        return pending

    def _count_late_replies(self) -> None:
        """Commands that timed out but were answered since (the gimbal hears us, only slowly), and
        those given up for good: no reply within the time one command lasts."""
        now = time.monotonic()
        kept: deque[tuple[float, PendingReply]] = deque()
        for sent_at, waiter in self._overdue:
            if waiter.done:
                if waiter.late:
                    self.stats["late_replies"] += 1
                self.watchdog.replied(late=waiter.late)
            elif now - sent_at >= SPEED_COMMAND_LASTS_S:
                self.stats["unanswered"] += 1
                self.watchdog.unanswered()
            else:
                kept.append((sent_at, waiter))
        self._overdue = kept

    def _collect(self, pending: PendingReply | None) -> None:
        """Account for the previous tick's reply, and for the replies still outstanding."""
        self._count_late_replies()
        if pending is None:
            return
        self._client.cancel(pending)
        if not pending.done:
            self.stats["reply_timeouts"] += 1
            self._overdue.append((time.monotonic() - 1.0 / self.rate_hz, pending))
            self.watchdog.timed_out()
            return
        try:
            self._client.result(pending)
            self.stats["replies"] += 1
            self.watchdog.replied()
        except BusError:
            raise
        except GimbalError as exc:  # a NACK or an undecodable reply: counted, streaming goes on
            self.stats["reply_errors"] += 1
            self.watchdog.replied(nack=True)
            log.warning("speed command reply: %s", exc)
