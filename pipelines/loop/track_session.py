"""The run behind ``gimbaltrack track``: a frame source driving the shared ``Loop`` against an
open gimbal client, with the outputs attached as sinks.

Every output is written as the run goes, so a run that fails or is interrupted keeps what it
had; ``finish`` always stops the gimbal (zero speed, release) before anything else.
"""
from __future__ import annotations

import dataclasses
import logging
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gimbal.errors import GimbalError
from gimbal.signals import deferred_signals
from gimbal.watchdog import DEFAULT_TIMEOUT_S
from pipelines.control.camera import CameraModel
from pipelines.control.controller import ControlConfig, make_controller
from pipelines.control.gimbal_link import GimbalLink, Signs
from pipelines.control.tuning import settings_of
from pipelines.loop import (
    Loop, PlotSink, ProgressSink, Recorder, SummarySink, TelemetrySink, VideoSink, loop_panels,
)
from pipelines.loop.acquire import CAMERA_MOTION_FRACTION, AcquiringSubject, StartConfirmer
from pipelines.loop.link import LinkNotices, LinkSink, link_health
from pipelines.loop.record import FrameRecord
from pipelines.outputs.latency import latency_percentiles
from pipelines.outputs.summary import write_summary
from pipelines.sources import Frame, FrameSource
from tracker import SubjectTracker, make_tracker
from tracker.detectors import Detector, make_detector

if TYPE_CHECKING:
    from gimbal.client import GimbalClient
    from pipelines.outputs.can_log import CanLogWriter

log = logging.getLogger(__name__)

SUMMARY_EVERY_S = 1.0
#: The annotated video's default width: enough to review the run, and cheap to encode (a frame at
#: full 720p or 4K size costs several times as much, docs/outputs.md).
DEFAULT_VIDEO_WIDTH = 640
FEEDBACK_MODES = ("auto", "on", "off")


@dataclass
class TrackOptions:
    """What the user chose; defaults are what ``gimbaltrack track SOURCE`` does."""

    out_dir: Path
    roi: tuple[int, int, int, int] | None = None
    detect: str | None = None
    pick: str = "central"
    tracker: str = "default"
    model_dir: Path | None = None
    controller: str = "pid"
    hfov_deg: float | None = None
    rate_hz: float = 25.0
    max_speed_dps: float | None = None  # None: the controller's default
    record: bool = False
    realtime: bool = False
    attitude_feedback: str = "auto"
    yaw_sign: int = 1  # -1 for a gimbal whose positive yaw speed turns the other way (seen on an RS 5)
    pitch_sign: int = 1
    yaw_attitude_sign: int = 1  # -1 for a gimbal that reports its yaw with the opposite sign
    pitch_attitude_sign: int = 1
    max_frames: int | None = None
    video: bool = True
    video_width: int | None = DEFAULT_VIDEO_WIDTH  # None: the source's own size
    progress: bool = True
    bus_timeout: float = DEFAULT_TIMEOUT_S  # silence before the gimbal is released (taken back when it answers)

    @property
    def signs(self) -> Signs:
        return Signs(self.yaw_sign, self.pitch_sign, self.yaw_attitude_sign, self.pitch_attitude_sign)


def control_config(max_speed_dps: float | None) -> ControlConfig:
    """The controller's defaults, with the speed limit the user chose; the acceleration limit is
    raised only as far as the zero-speed ramp on loss needs to stay within it."""
    base = ControlConfig()
    if max_speed_dps is None:
        return base
    return dataclasses.replace(base, max_speed_dps=max_speed_dps,
                               max_accel_dps2=max(base.max_accel_dps2, max_speed_dps / base.ramp_s))


def make_subject(options: TrackOptions) -> tuple[Detector | None, SubjectTracker]:
    """The run's detector (None without ``detect``) and tracker, which runs the detector itself on
    every frame while the subject is lost. Missing model files or an unknown name raise
    FileNotFoundError or ValueError: a front end makes them before it creates the output folder."""
    detector = make_detector(options.detect, options.model_dir) if options.detect else None
    return detector, make_tracker(options.tracker, options.model_dir, detector)


class _CanLogCheck:
    """Ends the run when the CAN log can no longer be written (its writer runs on a thread)."""

    name = "CAN log"

    def __init__(self, can_log: CanLogWriter) -> None:
        self.can_log = can_log

    def on_frame(self, record: FrameRecord, frame: Frame) -> None:
        if self.can_log.error is not None:
            raise OSError(f"cannot write the CAN log {self.can_log.path}: {self.can_log.error}")

    def close(self) -> None:
        """The log is the bus's: the command stops it after the client."""


class TrackSession:
    """One tracking run against an open source and an open gimbal client; ``subject`` is
    ``make_subject(options)``. ``loop`` is the run's ``Loop``: an operator's commands reach it
    through ``loop.submit``."""

    def __init__(self, options: TrackOptions, source: FrameSource, client: GimbalClient,
                 bus_description: str, subject: tuple[Detector | None, SubjectTracker],
                 can_log: CanLogWriter | None = None) -> None:
        self.options = options
        self.source = source
        self.client = client
        self.bus_description = bus_description
        width, height = source.size
        detector, tracker = subject
        confirmer = StartConfirmer(
            max_moving_fraction=CAMERA_MOTION_FRACTION if options.detect == "motion" else None)
        # live and realtime frames carry monotonic capture times; fast file playback stamps on read
        self._monotonic_stamps = source.is_live or options.realtime
        self.subject = AcquiringSubject(tracker, detector, source.size, roi=options.roi, pick=options.pick,
                                        confirmer=confirmer, video_time=not self._monotonic_stamps)
        self.camera = CameraModel(width, height, hfov_deg=options.hfov_deg)
        self.link = GimbalLink(client, rate_hz=options.rate_hz, signs=options.signs, bus_timeout=options.bus_timeout)
        self.recorder = Recorder(client, requested=options.record)
        self.feedback = (source.is_live if options.attitude_feedback == "auto"
                         else options.attitude_feedback == "on")
        self.loop = Loop(self.subject, make_controller(options.controller, camera=self.camera,
                                                       config=control_config(options.max_speed_dps)),
                         self.link, feedback=self.feedback, recorder=self.recorder,
                         video_fps=None if source.is_live else source.playback_fps,
                         dropped=lambda: source.dropped)
        self.reason = "running"
        self.error: str | None = None
        out = options.out_dir
        self.paths = {"telemetry": out / "telemetry.jsonl", "can_log": out / "can.log",
                      "summary": out / "summary.json", "plot": out / "plot.png"}
        for stale in (self.paths["plot"], out / "annotated.avi"):  # an earlier run's, which this one may not rewrite
            stale.unlink(missing_ok=True)
        # the order is the contract: telemetry first, then the frame is counted, then the rest
        self.outputs = [self.loop.attach(TelemetrySink(self.paths["telemetry"]))]
        self.counts = SummarySink(lambda sync: self.write_summary(sync), SUMMARY_EVERY_S)
        self.loop.attach(self.counts)
        self.plot = self.loop.attach(PlotSink(self.paths["plot"], loop_panels(self.feedback)))
        if options.video:
            self.paths["video"] = out / "annotated.avi"
            self.outputs.append(self.loop.attach(VideoSink(self.paths["video"], source.size, source.playback_fps,
                                                           options.video_width)))
        if can_log is not None:
            self.loop.attach(_CanLogCheck(can_log))
        self.progress = ProgressSink(source.frame_count, enabled=options.progress)
        self.loop.attach(LinkSink(LinkNotices(options.bus_timeout, self._warn), self.recorder))
        self.loop.attach(self.progress)

    def _warn(self, line: str) -> None:
        self.progress.reporter.note(f"gimbaltrack track: warning: {line}")

    @property
    def frames(self) -> int:
        return self.counts.frames

    # -- the run -------------------------------------------------------------------------
    def start(self) -> None:
        """Subscribe to the attitude push and start the speed keep-alive."""
        self.link.start()

    def run(self) -> None:
        """Process frames until the source ends, ``max_frames`` or ``loop.stop``; exceptions propagate."""
        for frame in self.source:
            with deferred_signals():  # a frame's telemetry, video and counts are written whole
                self.step(frame)
            if self.loop.stop_reason is not None:
                self.reason = self.loop.stop_reason
                return
            if self.options.max_frames is not None and self.frames >= self.options.max_frames:
                self.reason = "max frames reached"
                return
        self.reason = "end of source"

    def step(self, frame: Frame) -> FrameRecord:
        """One frame through the loop, its outputs written."""
        stamp = frame.timestamp if self._monotonic_stamps else self.loop.clock()
        return self.loop.step(frame, stamp)

    # -- the end -------------------------------------------------------------------------
    def finish(self, reason: str | None = None, error: str | None = None) -> dict[str, Any]:
        """Stop the gimbal, stop recording, finalise every output; safe to call after any failure.
        Ctrl-C and terminating signals during it are dropped: a stop is already under way."""
        with deferred_signals(deliver=False):
            return self._finish(reason, error)

    def _finish(self, reason: str | None, error: str | None) -> dict[str, Any]:
        if reason:
            self.reason = reason
        self.error = error or self.error
        try:
            self.link.stop()
        except (GimbalError, OSError) as exc:
            log.warning("could not send the stop command: %s", exc)
        self.loop.cancel_submitted()
        try:
            self.recorder.finish()
        except OSError as exc:  # a bus that went away
            self.recorder.status["error"] = str(exc)
        self.progress.finish(self.reason)
        self.progress.close()
        for sink in self.outputs:  # what was flushed before a failure is kept
            self._finalise(sink.name, sink.close)
        if not (self.plot.written and self._finalise(self.plot.name, self.plot.close)):
            self.paths.pop("plot", None)  # a run that ended before its first frame has nothing to plot
        try:
            return self.write_summary()
        except OSError as exc:  # the previous rewrite, if any, stays in place
            self._output_failed("summary", exc)
            return self._summary()

    def _finalise(self, what: str, step: Callable[[], None]) -> bool:
        """Run an output's last step; a failure (a full disk) is recorded and the others still run."""
        try:
            step()
        except OSError as exc:
            self._output_failed(what, exc)
            return False
        return True

    def _output_failed(self, what: str, exc: OSError) -> None:
        self.reason, self.error = "output failed", self.error or f"{what}: {exc.strerror or exc}"

    def write_summary(self, sync: bool = True) -> dict[str, Any]:
        """Write the summary as it stands (atomically; ``sync``: fsync it) and return it."""
        self.counts.written()
        summary = self._summary()
        write_summary(self.paths["summary"], summary, sync)
        return summary

    def _summary(self) -> dict[str, Any]:
        """The summary as it stands."""
        elapsed = self.loop.clock() - self.loop.started
        counts = self.counts
        return {
            "status": self.reason, "error": self.error,
            "source": self.source.description, "live": self.source.is_live,
            "bus": self.bus_description, "tracker": self.subject.name, "controller": self.options.controller,
            "attitude_feedback": self.feedback, "loop": "closed" if self.feedback else "open",
            "frames": counts.frames, "elapsed_s": elapsed, "fps": counts.frames / elapsed if elapsed > 0 else None,
            "frames_dropped": counts.dropped,
            "frames_expected": None if self.source.is_live else self.source.frame_count,
            "states": dict(counts.states), "first_acquired_s": self.loop.first_acquired_s,
            "angular_error_deg": counts.angular_error(),
            "latency_ms": {k: (v * 1000.0 if isinstance(v, float) else v)
                           for k, v in latency_percentiles(self.link.latencies()).items()},
            "speed_commands": dict(self.link.stats()),
            "bus_health": link_health(self.link.health(), self.link.other_hosts()),
            "recording": self.recorder.status,
            "settings": settings_of(self.loop.controller.config),
            "outputs": {k: str(v) for k, v in self.paths.items()},
        }
