"""One task over several inputs: in this process, in worker processes on this machine, or on a Dask
cluster. Outcomes are shown in input order whatever finishes first; a failing input is an outcome
naming it, not the end of the batch; a stop (Ctrl-C, SIGTERM) asks the workers to stop, shows what
finished and goes on unwinding."""
from __future__ import annotations

import logging
import multiprocessing
import os
import signal
import threading
import traceback
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from contextlib import contextmanager
from dataclasses import dataclass
from multiprocessing.synchronize import Event
from typing import Any, TypeVar

from gimbal.signals import deferred_signals, exit_on_signals

T = TypeVar("T")

#: Thread pools of OpenMP, OpenBLAS and MKL, read once when numpy or OpenCV loads: a worker's fps is
#: of one thread, as in a serial run (Dask's nanny sets the same variables for its workers).
ONE_THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")

#: How long stopped workers have to hand back what they were doing (a track run finishes its outputs).
STOP_GRACE_S = 15.0
#: How often an idle or busy worker checks that the command that started it is still there.
PARENT_CHECK_S = 0.5
EXIT_PARENT_GONE = 1


class InputFailed(Exception):
    """What a task raises for an input it cannot do: the message names the input, for the user."""


class BatchError(Exception):
    """The batch cannot run at all (no Dask installed, a scheduler that cannot be reached)."""


@dataclass(frozen=True)
class Outcome:
    """What became of one input: its ``result``, or an ``error`` line (``detail``: a traceback when
    the task failed in a way it did not word itself, a bug)."""

    index: int
    name: str
    result: Any = None
    error: str | None = None
    detail: str | None = None


def run_batch(task: Callable[[T], Any], inputs: Sequence[tuple[str, T]], *, jobs: int = 1,
              scheduler: str | None = None, show: Callable[[Outcome], None],
              finished: Callable[[Outcome], None] | None = None) -> list[Outcome]:
    """Run ``task`` on each ``(name, item)`` of ``inputs`` and return the outcomes in input order.

    ``jobs`` 1 runs here, one input after the other; more runs that many worker processes (spawned,
    one thread each); ``scheduler`` (an address) runs on that Dask cluster instead. ``task`` and the
    items must pickle for the last two. ``finished`` sees each outcome as it arrives, ``show`` sees
    them in input order. On KeyboardInterrupt or a terminating signal the workers are asked to stop,
    what finished is shown (skipping what did not) and the exception goes on.
    """
    order = _InputOrder(show)
    on_done = order.add if finished is None else lambda outcome: (finished(outcome), order.add(outcome))
    try:
        if scheduler is not None:
            _on_dask(task, inputs, scheduler, on_done)
        elif jobs > 1 and len(inputs) > 1:
            _in_processes(task, inputs, min(jobs, len(inputs)), on_done)
        else:
            for index, (name, item) in enumerate(inputs):
                on_done(attempt(task, index, name, item))
    except BaseException:
        order.show_the_rest()
        raise
    return order.outcomes()


def attempt(task: Callable[[T], Any], index: int, name: str, item: T) -> Outcome:
    """``task(item)`` as an outcome; only a stop (KeyboardInterrupt, a signal's SystemExit) escapes."""
    try:
        return Outcome(index, name, task(item))
    except InputFailed as exc:
        return Outcome(index, name, error=str(exc))
    except Exception as exc:  # not worded by the task: a bug, named so that the other inputs go on
        return Outcome(index, name, error=f"{name}: {type(exc).__name__}: {exc}", detail=traceback.format_exc())


class _InputOrder:
    """Holds outcomes that arrive early until those before them are shown."""

    def __init__(self, show: Callable[[Outcome], None]) -> None:
        self._show = show
        self._held: dict[int, Outcome] = {}
        self._shown: list[Outcome] = []

    def add(self, outcome: Outcome) -> None:
        self._held[outcome.index] = outcome
        while (next_index := len(self._shown)) in self._held:
            self._shown.append(self._held.pop(next_index))
            self._show(self._shown[-1])

    def show_the_rest(self) -> None:
        """Show what is held, in order, over the gaps of inputs that never finished."""
        for index in sorted(self._held):
            self._show(self._held.pop(index))

    def outcomes(self) -> list[Outcome]:
        return list(self._shown)


# --- worker processes on this machine -------------------------------------------------------------

_stop_asked: Event | None = None  # in a worker process: set when the parent asks for a stop


def _in_processes(task: Callable[[T], Any], inputs: Sequence[tuple[str, T]], jobs: int,
                  on_done: Callable[[Outcome], None]) -> None:
    context = multiprocessing.get_context("spawn")  # fresh interpreters: the one-thread variables apply
    stop = context.Event()
    with _one_thread_environment():
        executor = ProcessPoolExecutor(jobs, mp_context=context, initializer=_start_worker,
                                       initargs=(stop, logging.getLogger().getEffectiveLevel()))
        try:
            pending = {executor.submit(_attempt_in_worker, task, index, name, item): (index, name)
                       for index, (name, item) in enumerate(inputs)}
        except BaseException:
            executor.shutdown(wait=False, cancel_futures=True)
            raise
    try:
        _collect(pending, on_done, timeout=None)
    except BaseException:
        with deferred_signals(deliver=False):  # a second Ctrl-C must not cut the stop short
            stop.set()
            for future in pending:
                future.cancel()
            _collect({f: v for f, v in pending.items() if not f.cancelled()}, on_done, timeout=STOP_GRACE_S)
            executor.shutdown(wait=True, cancel_futures=True)
        raise
    executor.shutdown(wait=True)


def _collect(pending: dict[Future, tuple[int, str]], on_done: Callable[[Outcome], None],
             timeout: float | None) -> None:
    """Hand each finished future's outcome to ``on_done`` until none is left or ``timeout`` passes."""
    while pending:
        done, _ = wait(pending, timeout=timeout, return_when=FIRST_COMPLETED)
        if not done:
            return
        for future in done:
            index, name = pending.pop(future)
            if future.cancelled():
                continue
            try:
                outcome = future.result()
            except Exception as exc:  # the worker process died (killed, out of memory, a crash in C)
                outcome = Outcome(index, name, error=f"{name}: its worker process died ({type(exc).__name__}: {exc})")
            if outcome is not None:
                on_done(outcome)


@contextmanager
def _one_thread_environment() -> Iterator[None]:
    """The one-thread variables set for the processes started inside, then put back."""
    before = {name: os.environ.get(name) for name in ONE_THREAD_VARIABLES}
    os.environ.update(dict.fromkeys(ONE_THREAD_VARIABLES, "1"))
    try:
        yield
    finally:
        for name, value in before.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


def _start_worker(stop: Event, log_level: int) -> None:
    """A worker process: Ctrl-C in a terminal reaches every process of the group, but the parent
    decides; it asks for a stop through ``stop``, which becomes a SIGTERM while a task runs. It
    logs as the command does (``-v``, ``--debug``)."""
    global _stop_asked
    _stop_asked = stop
    logging.basicConfig(level=log_level, format="%(levelname)s %(name)s: %(message)s")
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)  # idle: a stop has nothing to cut short
    one_thread()
    threading.Thread(target=_terminate_on_stop, args=(stop, os.getppid()), name="stop-watch", daemon=True).start()


def _terminate_on_stop(stop: Event, parent: int) -> None:
    """A stop becomes a SIGTERM; a parent that died without asking (killed, SIGKILL) ends the
    worker at once: nobody reads its result any more, and it would run, or wait to write, for ever."""
    while not stop.wait(PARENT_CHECK_S):
        if os.getppid() != parent:
            os._exit(EXIT_PARENT_GONE)
    os.kill(os.getpid(), signal.SIGTERM)


def _attempt_in_worker(task: Callable[[T], Any], index: int, name: str, item: T) -> Outcome | None:
    """``attempt`` in a worker process; None when the stop came first. A SIGTERM while the task
    runs unwinds it (a track run finishes its outputs and returns); one that cuts a task short
    without a result of its own leaves no outcome."""
    try:
        with exit_on_signals():
            if _stop_asked is not None and _stop_asked.is_set():  # asked before this task could see it
                return None
            return attempt(task, index, name, item)
    except SystemExit:
        return None


def one_thread() -> None:
    """OpenCV on one thread in this process (its pool is sized on first use, so this works late)."""
    import cv2  # here, not at the top: the spawned worker's environment is set first

    cv2.setNumThreads(1)


# --- a Dask cluster -------------------------------------------------------------------------------

def _on_dask(task: Callable[[T], Any], inputs: Sequence[tuple[str, T]], address: str,
             on_done: Callable[[Outcome], None]) -> None:
    with connect(address) as client:
        from distributed import as_completed  # installed: connect() says so in words otherwise

        futures = {client.submit(_attempt_on_dask, task, index, name, item, pure=False): (index, name)
                   for index, (name, item) in enumerate(inputs)}
        try:
            for future in as_completed(futures):
                index, name = futures[future]
                try:
                    outcome = future.result()
                except Exception as exc:  # lost with its worker, or the task could not load there
                    outcome = Outcome(index, name, error=f"{name}: failed on the Dask cluster ({type(exc).__name__}: {exc})")
                on_done(outcome)
        except BaseException:
            client.cancel(list(futures))  # what runs already finishes on the cluster, unseen
            raise


def connect(address: str) -> Any:
    """A ``distributed.Client`` on the scheduler at ``address``; ``BatchError`` in words when Dask is
    not installed, the address is malformed or nothing answers within Dask's connect timeout
    (``distributed.comm.timeouts.connect``, e.g. ``DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT=5s``)."""
    try:
        from distributed import Client
    except ImportError:
        raise BatchError("--scheduler needs Dask's distributed package: pip install 'gimbaltrack[dask]'") from None
    try:
        return Client(address)
    except ValueError as exc:
        raise BatchError(f"--scheduler {address!r} is not a Dask scheduler address ({exc}; e.g. "
                         "tcp://scheduler-host:8786)") from None
    except OSError as exc:
        raise BatchError(f"no Dask scheduler answers at {address} ({exc})") from None


def _attempt_on_dask(task: Callable[[T], Any], index: int, name: str, item: T) -> Outcome:
    one_thread()
    return attempt(task, index, name, item)
