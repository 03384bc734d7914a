"""Signals for a process that drives a gimbal: polite terminations unwind like Ctrl-C, and a unit
of work (one frame and its outputs, the final clean-up) is not cut in half by one."""
from __future__ import annotations

import signal
import threading
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from types import FrameType

#: What ends a process politely besides Ctrl-C: ``kill``, a closed terminal (SIGHUP), Ctrl-\ (SIGQUIT).
TERMINATING_SIGNALS = tuple(getattr(signal, name) for name in ("SIGTERM", "SIGHUP", "SIGQUIT")
                            if hasattr(signal, name))


class SignalExit(SystemExit):
    """The ``SystemExit(128 + signum)`` a terminating signal turns into (``exit_on_signals``)."""

    @property
    def signal_name(self) -> str:
        """``SIGTERM`` for 143, and so on."""
        return signal.Signals(int(self.code) - 128).name  # type: ignore[arg-type]


@contextmanager
def exit_on_signals(signals: Iterable[int] = TERMINATING_SIGNALS) -> Iterator[None]:
    """Turn the given signals into ``SignalExit(128 + signum)`` in the main thread, so ``with
    GimbalClient(...)`` blocks unwind and send the safety stop (Ctrl-C already raises
    ``KeyboardInterrupt``). Outside the main thread it changes nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum: int, frame: FrameType | None) -> None:
        raise SignalExit(128 + signum)

    previous = {s: signal.signal(s, handler) for s in signals}
    try:
        yield
    finally:
        for s, old in previous.items():
            signal.signal(s, old)


@contextmanager
def deferred_signals(signals: Iterable[int] = (signal.SIGINT, *TERMINATING_SIGNALS),
                     deliver: bool = True) -> Iterator[list[int]]:
    """Hold the given signals until the block ends, then deliver them to the handlers in place
    before it, so a unit of work (one frame and its outputs) is done whole or not at all; with
    ``deliver=False`` they are dropped instead (for the clean-up after a stop was already asked
    for: a second Ctrl-C must not cut it short). Yields the list of signals held so far: clearing
    it drops them. Outside the main thread it changes nothing."""
    pending: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield pending
        return
    previous = {s: signal.signal(s, lambda signum, frame: pending.append(signum)) for s in signals}
    try:
        yield pending
    finally:
        for s, old in previous.items():
            signal.signal(s, old)
        for signum in dict.fromkeys(pending) if deliver else ():
            signal.raise_signal(signum)


@contextmanager
def blocked_signals(signals: Iterable[int] = (signal.SIGINT, *TERMINATING_SIGNALS)) -> Iterator[None]:
    """Keep the given signals pending at the OS level until the block ends, then let them arrive.
    For loading numpy, SciPy and OpenCV: some of their modules swap signal handlers while they
    load, and a Ctrl-C landing then could be lost or turned into an import error. Threads started
    inside the block keep them blocked, so the main thread is the one that receives them. Where
    the OS cannot block signals, it changes nothing."""
    if not hasattr(signal, "pthread_sigmask") or threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, set(signals))
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)
