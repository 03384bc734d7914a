"""One step of the closed loop, shared by every front end: a frame's estimate, the controller's
command, the command on the bus, and a ``FrameRecord`` handed to the attached sinks.

Thread contract: ``step`` and the operator methods run on the loop's thread. Another thread (a
console, a web handler) hands work over with ``submit(fn)``: it runs on the loop's thread at the
start of the next step, and its result or exception comes back through the returned ``Future``.
"""
from __future__ import annotations

import queue
import time
from collections.abc import Callable
from concurrent.futures import Future
from typing import TYPE_CHECKING, Any, Protocol, TypeVar

from pipelines.control.controller import RateCommand
from pipelines.loop.record import PAUSED, FrameRecord

if TYPE_CHECKING:
    from pipelines.control.controller import ControlConfig, Controller
    from pipelines.control.gimbal_link import GimbalLink
    from pipelines.loop.recording import Recorder
    from pipelines.loop.sinks import Sink
    from pipelines.sources import Frame
    from tracker.runtime.boxes import Box
    from tracker.detectors import Detection
    from tracker.runtime.estimate import TargetEstimate

T = TypeVar("T")
Note = dict[str, Any]

#: What ``Loop.stop`` records as the reason when the operator gives none.
OPERATOR_STOP = "stopped by the operator"


class Subject(Protocol):
    """What the loop follows: the tracker, with however the run chooses the subject."""

    @property
    def name(self) -> str: ...

    @property
    def candidates(self) -> tuple[Detection, ...]:
        """The detector's candidates of the last ``estimate`` call (empty when it did not run)."""

    def start(self, box: Box) -> None:
        """Follow the subject in ``box`` from the next frame on (drop the current one)."""

    def estimate(self, frame: Frame, t: float) -> TargetEstimate | None:
        """The subject in ``frame``, taken at ``t`` on the loop's clock; None while none is chosen."""


class Loop:
    """Frames in, commands out. ``feedback``: the camera rides on the gimbal, so the attitude at
    a frame's time places the subject in the world; without it (recorded footage, whose image does
    not move with the gimbal) the attitude is a fixed (0, 0). ``video_fps``: the frames come from
    a recording at this rate (gives ``FrameRecord.t_video``); ``dropped``: the source's count of
    frames it dropped. ``clock`` is the monotonic clock the controller, the frames' times and the
    attitude pushes share."""

    def __init__(self, subject: Subject, controller: Controller, gimbal: GimbalLink, *,
                 feedback: bool = True, recorder: Recorder | None = None, video_fps: float | None = None,
                 dropped: Callable[[], int] = lambda: 0, clock: Callable[[], float] = time.monotonic) -> None:
        self.subject = subject
        self.controller = controller
        self.gimbal = gimbal
        self.feedback = feedback
        self.recorder = recorder
        self.video_fps = video_fps
        self.dropped = dropped
        self.clock = clock
        self.sinks: list[Sink] = []
        self.started = clock()
        self.first_acquired_s: float | None = None  # from the loop's start
        self.stop_reason: str | None = None  # set by ``stop``: the driver ends the run after this step
        self.paused = False  # set by ``pause``: no command is sent until ``resume``
        self._work: queue.SimpleQueue[tuple[Future[Any], Callable[[], Any], Note | None]] = queue.SimpleQueue()

    # -- wiring --------------------------------------------------------------------------
    def attach(self, sink: Sink) -> Sink:
        """Hand every later record to ``sink`` (after those attached before it)."""
        self.sinks.append(sink)
        return sink

    def submit(self, fn: Callable[[], T], note: Note | None = None) -> Future[T]:
        """Run ``fn`` on the loop's thread at the start of the next step; safe from any thread.
        ``note`` (what an operator did, JSON-ready) goes into that step's record, with the
        ``error`` if ``fn`` raised."""
        future: Future[T] = Future()
        self._work.put((future, fn, note))
        return future

    # -- what an operator does (on the loop's thread: call them through ``submit``) ------
    def start_tracking(self, box: Box) -> None:
        """Follow the subject in ``box`` from the next frame on."""
        self.subject.start(box)

    def start_recording(self) -> None:
        self._recorder().start()

    def stop_recording(self) -> None:
        self._recorder().stop()

    def stop(self, reason: str = OPERATOR_STOP) -> None:
        """End the run after the current step (the driver stops the gimbal and finalises)."""
        self.stop_reason = reason

    def pause(self) -> None:
        """Zero speed, then release: the gimbal holds where it is. Frames go on being tracked;
        no command is sent until ``resume`` (the state reads ``paused``)."""
        if not self.paused:
            self.paused = True
            self.gimbal.pause()

    def resume(self) -> None:
        """Follow again after ``pause``: the controller starts from rest on a new keep-alive."""
        if self.paused:
            self.controller.reset()
            self.gimbal.resume()
            self.paused = False

    def recenter(self) -> None:
        """Pause, then send the gimbal home (the protocol's recenter); ``resume`` to follow again."""
        self.pause()
        self.gimbal.recenter()

    def retune(self, config: ControlConfig) -> None:
        """New limits, gains and dead band from this step on (an operator's live settings)."""
        self.controller.retune(config)

    def _recorder(self) -> Recorder:
        if self.recorder is None:
            raise RuntimeError("this loop has no camera to record with")
        return self.recorder

    # -- the step ------------------------------------------------------------------------
    def step(self, frame: Frame, t: float) -> FrameRecord:
        """One frame captured at ``t``: submitted work, track, control, stream the setpoint, then
        the record to every sink."""
        notes = self._run_submitted()
        estimate = self.subject.estimate(frame, t)
        if self.paused:  # the gimbal holds: the keep-alive is stopped, nothing is sent
            command = RateCommand(0.0, 0.0, stamp=t, mode=PAUSED)
        else:
            attitude = self.gimbal.attitude_at(t) if self.feedback else (0.0, 0.0)
            command = self.controller.update(estimate, attitude, self.clock())
            self.gimbal.send(command, stamp=t)
        if estimate is not None and estimate.found and self.first_acquired_s is None:
            self.first_acquired_s = self.clock() - self.started
            if self.recorder is not None:
                self.recorder.on_acquired()
        record = FrameRecord(
            index=frame.index, t=t, t_run=self.clock() - self.started,
            t_video=None if self.video_fps is None else frame.index / self.video_fps,
            estimate=estimate, command=command, attitude=self.gimbal.latest(), dropped=self.dropped(),
            recording=self.recorder is not None and self.recorder.active,
            candidates=self.subject.candidates, paused=self.paused, operator=notes,
            bus=self.gimbal.health(), other_hosts=self.gimbal.other_hosts())
        for sink in self.sinks:
            sink.on_frame(record, frame)
        return record

    def _run_submitted(self) -> tuple[Note, ...]:
        """The submitted work, in order; an exception goes to its ``Future`` (and its note), not
        into the loop. The notes of the work that ran."""
        notes: list[Note] = []
        while True:
            try:
                future, fn, note = self._work.get_nowait()
            except queue.Empty:
                return tuple(notes)
            if future.set_running_or_notify_cancel():
                try:
                    future.set_result(fn())
                except Exception as exc:  # noqa: BLE001 (handed to the submitter)
                    future.set_exception(exc)
                    note = None if note is None else {**note, "error": str(exc)}
                if note is not None:
                    notes.append(note)

    def cancel_submitted(self) -> None:
        """Cancel the work that will not run now (the run ended): no submitter is left waiting."""
        while True:
            try:
                future, _, _ = self._work.get_nowait()
            except queue.Empty:
                return
            future.cancel()
