"""The session behind ``gimbaltrack track``: frames -> tracker -> control -> gimbal, with outputs.

Every output is written as the run goes, so a run that fails or is interrupted keeps what it
had; ``finish`` always stops the gimbal (zero speed, release) before anything else.
"""
from __future__ import annotations

import dataclasses
import logging
import math
import queue
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from gimbal.client import GimbalClient
from gimbal.errors import GimbalError
from gimbal.messages import ParameterPush
from gimbal.signals import deferred_signals
from pipelines.acquire import CAMERA_MOTION_FRACTION, StartConfirmer, pick_candidate
from gimbal.keepalive import SpeedStreamer
from pipelines.control import AttitudeHistory, CameraModel, ControlConfig, make_controller
from pipelines.control.controller import RateCommand
from pipelines.control.tuning import settings_of
from pipelines.outputs.annotated_video import BackgroundVideoWriter, rates_text
from pipelines.outputs.can_log import CanLogWriter
from pipelines.outputs.latency import latency_percentiles
from pipelines.outputs.plot import write_timeseries_png
from pipelines.outputs.summary import write_summary
from pipelines.outputs.telemetry import TelemetryWriter, estimate_fields
from pipelines.progress import ProgressReporter
from pipelines.sources import Frame, FrameSource
from tracker import SubjectTracker, make_tracker
from tracker.detectors import Detector, make_detector
from tracker.datasets import ASSUMED_FPS
from tracker.estimate import TargetEstimate

log = logging.getLogger(__name__)

SUMMARY_EVERY_S = 1.0
#: The annotated video's default width: enough to review the run, and cheap to encode (a 720p
#: frame at full size costs 3.6-5 ms of CPU, a 4K one several times that).
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


@dataclass(frozen=True)
class SessionRecord:
    """One frame as the session's extra sinks (the console) get it."""

    index: int
    t: float
    state: str
    estimate: TargetEstimate | None
    command: RateCommand
    candidates: tuple[tuple[float, ...], ...]


@dataclass
class _Series:
    """What the plot shows, one value per frame."""

    t: list[float] = field(default_factory=list)
    yaw_error: list[float] = field(default_factory=list)
    pitch_error: list[float] = field(default_factory=list)
    yaw_rate: list[float] = field(default_factory=list)
    pitch_rate: list[float] = field(default_factory=list)
    # the angular error hypot(yaw, pitch) so far, kept as it goes for the summary
    error_count: int = 0  # frames whose command had a subject to measure the error against
    error_sum: float = 0.0
    error_max: float | None = None


def control_config(max_speed_dps: float | None) -> ControlConfig:
    """The controller's defaults, with the speed limit the user chose; the acceleration limit is
    raised only as far as the zero-speed ramp on loss needs to stay within it."""
    base = ControlConfig()
    if max_speed_dps is None:
        return base
    return dataclasses.replace(base, max_speed_dps=max_speed_dps,
                               max_accel_dps2=max(base.max_accel_dps2, max_speed_dps / base.ramp_s))


def signed_attitude(yaw: float, pitch: float, options: TrackOptions) -> tuple[float, float]:
    """A reported yaw/pitch in this project's convention (yaw positive to the right, pitch up).
    Independent of the speed signs: a gimbal that turns the other way for a positive speed
    command (``yaw_sign``) may still report its angles the usual way, as one RS 5 does."""
    return yaw * options.yaw_attitude_sign, pitch * options.pitch_attitude_sign


def make_subject(options: TrackOptions) -> tuple[Detector | None, SubjectTracker]:
    """The run's detector (None without ``detect``) and tracker, which runs the detector itself on
    every frame while the subject is lost. Missing model files or an unknown name raise
    FileNotFoundError or ValueError: a front end makes them before it creates the output folder."""
    detector = make_detector(options.detect, options.model_dir) if options.detect else None
    return detector, make_tracker(options.tracker, options.model_dir, detector)


class TrackSession:
    """One tracking run against an open source and an open gimbal client; ``subject`` is
    ``make_subject(options)``."""

    def __init__(self, options: TrackOptions, source: FrameSource, client: GimbalClient,
                 bus_description: str, subject: tuple[Detector | None, SubjectTracker],
                 can_log: CanLogWriter | None = None) -> None:
        self.options = options
        self.can_log = can_log  # the bus's log: its write failure ends the run (OSError)
        self.source = source
        self.client = client
        self.bus_description = bus_description
        width, height = source.size
        self.camera = CameraModel(width, height, hfov_deg=options.hfov_deg)
        self.controller = make_controller(options.controller, camera=self.camera,
                                          config=control_config(options.max_speed_dps))
        self.detector, self.tracker = subject
        self._confirmer = StartConfirmer(
            max_moving_fraction=CAMERA_MOTION_FRACTION if options.detect == "motion" else None)
        self.feedback = (source.is_live if options.attitude_feedback == "auto"
                         else options.attitude_feedback == "on")
        self.history = AttitudeHistory()
        # live and realtime frames carry monotonic capture times; fast file playback stamps on read
        self._monotonic_stamps = source.is_live or options.realtime
        self.states: Counter[str] = Counter()
        self.series = _Series()
        self.frames = 0
        self.first_acquired_s: float | None = None
        self.recording: dict[str, Any] = {"requested": options.record}
        self.reason = "running"
        self.error: str | None = None
        self._estimate: TargetEstimate | None = None
        self._started = time.monotonic()
        self._last_summary = 0.0
        self._streamer = None
        self._stopped_streamers: list[SpeedStreamer] = []  # paused ones: their counts stay in the summary
        # an operator's hands (the console): work run on this thread at the start of a step
        self._work: queue.SimpleQueue[tuple[Callable[[], Any], dict[str, Any] | None]] = queue.SimpleQueue()
        self.paused = False
        self.stop_reason: str | None = None
        self.candidates: tuple[tuple[float, ...], ...] = ()  # the detector's boxes of the last frame
        self._selected: tuple[float, ...] | None = None
        self.sinks: list[Any] = []  # more outputs, each ``on_frame(record, frame)`` after the telemetry
        self._progress = ProgressReporter(source.frame_count, enabled=options.progress)
        out = options.out_dir
        self.paths = {"telemetry": out / "telemetry.jsonl", "can_log": out / "can.log",
                      "summary": out / "summary.json", "plot": out / "plot.png"}
        self.telemetry = TelemetryWriter(self.paths["telemetry"])
        for stale in (self.paths["plot"], out / "annotated.avi"):  # an earlier run's, which this one may not rewrite
            stale.unlink(missing_ok=True)
        self.video: BackgroundVideoWriter | None = None
        if options.video:
            self.paths["video"] = out / "annotated.avi"
            self.video = BackgroundVideoWriter(self.paths["video"], source.size, source.fps or ASSUMED_FPS,
                                               options.video_width)

    # -- the run -------------------------------------------------------------------------
    def start(self) -> None:
        """Subscribe to the attitude push and start the speed keep-alive."""
        self.client.on_push(ParameterPush, self.history.on_push)
        self.client.set_push(True)
        self._streamer = self.client.speed_streamer(rate_hz=self.options.rate_hz)

    def run(self) -> None:
        """Process frames until the source ends or ``max_frames``; exceptions propagate."""
        for frame in self.source:
            with deferred_signals():  # a frame's telemetry, video and counts are written whole
                self.step(frame)
            if self.stop_reason is not None:
                self.reason = self.stop_reason
                return
            if self.options.max_frames is not None and self.frames >= self.options.max_frames:
                self.reason = "max frames reached"
                return
        self.reason = "end of source"

    def step(self, frame: Frame) -> None:
        """One frame: track, control, stream the setpoint, write the outputs."""
        notes = self._run_submitted()
        stamp = frame.timestamp if self._monotonic_stamps else time.monotonic()
        estimate = self._track(frame, stamp)
        if self.paused:  # the gimbal holds: the keep-alive is stopped, nothing is sent
            command = RateCommand(0.0, 0.0, stamp=stamp, mode="paused")
        else:
            attitude = self._attitude_at(stamp)
            command = self.controller.update(estimate, attitude, time.monotonic())
            self._streamer.set(command.yaw_dps * self.options.yaw_sign,
                               command.pitch_dps * self.options.pitch_sign, stamp=stamp)
        if estimate is not None and estimate.found and self.first_acquired_s is None:
            self.first_acquired_s = time.monotonic() - self._started
            if self.options.record:
                self._start_recording()
        state = "paused" if self.paused else estimate.state.value if estimate is not None else "acquiring"
        self._write_frame(frame, stamp, state, estimate, command, notes)
        if self.can_log is not None and self.can_log.error is not None:
            raise OSError(f"cannot write the CAN log {self.can_log.path}: {self.can_log.error}")
        self._progress.update(self.frames, lambda: f"{state:<9} yaw {command.yaw_dps:+6.1f} "
                                                   f"pitch {command.pitch_dps:+6.1f} deg/s")
        if time.monotonic() - self._last_summary >= SUMMARY_EVERY_S:
            self.write_summary(sync=False)

    def _track(self, frame: Frame, stamp: float) -> TargetEstimate | None:
        """None until the subject is chosen; then the tracker's estimate. A lost subject is found
        again by the tracker: a detection that looks like it (``SubjectTracker``), never merely the
        nearest one, so the subject's look is kept and another person's is not taken for it."""
        if self._selected is not None:  # an operator's choice
            box, self._selected = self._selected, None
            self._estimate = self.tracker.init(frame.image, box, stamp)
            return self._estimate
        self.candidates = ()
        if self._estimate is None:
            box = self.options.roi if self.options.roi is not None else self._detect(frame)
            if box is None:
                return None
            self._estimate = self.tracker.init(frame.image, box, stamp)
            return self._estimate
        self._estimate = self.tracker.update(frame.image, stamp)
        return self._estimate

    def _detect(self, frame: Frame) -> tuple[float, ...] | None:
        """A confirmed detection to start on, by the pick rule. Runs on every frame while acquiring
        (the motion detector needs consecutive frames)."""
        if self.detector is None:
            return None
        detections = self.detector.detect(frame.image)
        self.candidates = tuple(tuple(d.box) for d in detections)
        confirmed = self._confirmer.offer(detections, self.source.size)
        found = pick_candidate(confirmed, self.source.size, self.options.pick)
        return None if found is None else tuple(found.box)

    def _attitude_at(self, stamp: float) -> tuple[float, float] | None:
        """The gimbal's yaw/pitch at the frame's time when the camera rides on the gimbal; a fixed
        (0, 0) for recorded footage, whose image does not move with the gimbal."""
        if not self.feedback:
            return (0.0, 0.0)
        sample = self.history.at(stamp)
        if sample is None:
            return None
        return signed_attitude(sample.yaw, sample.pitch, self.options)

    def _write_frame(self, frame: Frame, stamp: float, state: str, estimate: TargetEstimate | None,
                     command: Any, notes: tuple[dict[str, Any], ...] = ()) -> None:
        """Telemetry first, then the frame is counted (summary and plot), then the video: the
        summary's ``frames`` are the telemetry's lines, whichever output fails."""
        attitude = self.history.latest()
        record: dict[str, Any] = {"frame": frame.index, "t": stamp,
                                  "t_run": time.monotonic() - self._started, "state": state}
        if not self.source.is_live:  # where the frame sits in the recording
            record["t_video"] = frame.index / (self.source.fps or ASSUMED_FPS)
        if estimate is not None:
            record.update(estimate_fields(estimate))
        known = not math.isnan(command.yaw_error_deg)  # NaN: no subject behind this frame's command
        record.update({"error_deg": [command.yaw_error_deg, command.pitch_error_deg] if known else None,
                       "rate_dps": [command.yaw_dps, command.pitch_dps], "mode": command.mode,
                       "attitude_deg": None if attitude is None else
                       [attitude.yaw, attitude.pitch, attitude.roll],
                       "attitude_t": None if attitude is None else attitude.timestamp,
                       "dropped": self.source.dropped})
        record["state"] = state  # paused, whatever the tracker says
        if notes:
            record["operator"] = list(notes)
        self.telemetry.write(record)
        self.frames += 1
        self.states[state] += 1
        s = self.series
        s.t.append(record["t_run"])
        s.yaw_error.append(command.yaw_error_deg)
        s.pitch_error.append(command.pitch_error_deg)
        s.yaw_rate.append(command.yaw_dps)
        s.pitch_rate.append(command.pitch_dps)
        if known:
            error = math.hypot(command.yaw_error_deg, command.pitch_error_deg)
            s.error_count += 1
            s.error_sum += error
            s.error_max = error if s.error_max is None else max(s.error_max, error)
        for sink in self.sinks:
            sink.on_frame(SessionRecord(frame.index, stamp, state, estimate, command, self.candidates), frame)
        if self.video is not None:  # labelled with the source's frame index and the recording's time
            shown_t = record.get("t_video", record["t_run"])
            shown = None if estimate is None else dataclasses.replace(estimate, frame_index=frame.index,
                                                                      timestamp=shown_t)
            rates = (command.yaw_dps, command.pitch_dps)
            if shown is not None:
                self.video.write(frame.image, shown, rates, [f"mode {command.mode}"])
            else:  # the same three lines, the frame's first
                self.video.write(frame.image, None, None, [f"#{frame.index} t={shown_t:.3f}s acquiring",
                                                           rates_text(rates), f"mode {command.mode}"])

    # -- an operator's actions (the console): through ``submit``, run on this thread ---------
    def submit(self, fn: Callable[[], Any], note: dict[str, Any] | None = None) -> None:
        """Run ``fn`` at the start of the next step; safe from any thread. ``note`` goes into that
        frame's telemetry (``operator``), with the ``error`` if ``fn`` raised."""
        self._work.put((fn, note))

    def _run_submitted(self) -> tuple[dict[str, Any], ...]:
        notes = []
        while True:
            try:
                fn, note = self._work.get_nowait()
            except queue.Empty:
                return tuple(notes)
            try:
                fn()
            except (GimbalError, ValueError, RuntimeError) as exc:
                note = None if note is None else {**note, "error": str(exc)}
            if note is not None:
                notes.append(note)

    def start_tracking(self, box: tuple[float, ...]) -> None:
        self._selected = tuple(box)

    def start_recording(self) -> None:
        if not self.recording.get("started") or self.recording.get("stopped"):
            self.recording.pop("stopped", None)
            self.recording.pop("stop_confirmed", None)
            self._start_recording()

    def stop_recording(self) -> None:
        if self.recording.get("started") and not self.recording.get("stopped"):
            self._camera_action(self.client.stop_recording, "stopped", "stop_confirmed", recording=False)

    @property
    def recording_on(self) -> bool:
        return bool(self.recording.get("started")) and not self.recording.get("stopped")

    def stop(self, reason: str) -> None:
        self.stop_reason = reason

    def pause(self) -> None:
        """Zero speed, then release (the keep-alive's stop); frames go on being tracked."""
        if not self.paused:
            self.paused = True
            self._streamer.stop()
            self._stopped_streamers.append(self._streamer)

    def resume(self) -> None:
        if self.paused:
            self.controller.reset()
            self._streamer = self.client.speed_streamer(rate_hz=self.options.rate_hz)
            self.paused = False

    def recenter(self) -> None:
        self.pause()
        self.client.recenter()

    def retune(self, config: ControlConfig) -> None:
        self.controller.retune(config)

    def streamers(self) -> list[SpeedStreamer]:
        """Every keep-alive of the run: those ``pause`` stopped, then the current one."""
        current = self._streamer is not None and all(s is not self._streamer for s in self._stopped_streamers)
        return [*self._stopped_streamers, self._streamer] if current else list(self._stopped_streamers)

    def latencies(self) -> list[float]:
        return [latency for streamer in self.streamers() for latency in streamer.latencies()]

    def speed_stats(self) -> dict[str, int]:
        summed: Counter[str] = Counter()
        for streamer in self.streamers():
            summed.update(streamer.stats)
        return dict(summed)

    # -- recording -----------------------------------------------------------------------
    def _start_recording(self) -> None:
        self._camera_action(self.client.start_recording, "started", "start_confirmed", recording=True)

    def _stop_recording(self) -> None:
        if self.recording["requested"] and self.first_acquired_s is None:
            self.recording["started"] = False
            self.recording["error"] = "the subject was never acquired"
        if not self.recording_on:  # never started, or an operator stopped it already
            return
        self._camera_action(self.client.stop_recording, "stopped", "stop_confirmed", recording=False)

    def _camera_action(self, action: Callable[[], None], done: str, confirmed: str, recording: bool) -> None:
        """Send a record start or stop, then ask the camera whether it is ``recording``. An answered
        action counts as done (so a start is always followed by a stop), confirmed or not."""
        try:
            action()
        except GimbalError as exc:
            self.recording[done] = False
            self.recording["error"] = str(exc)
            return
        self.recording[done] = True
        try:
            self.recording[confirmed] = self.client.camera_status() is recording
        except GimbalError as exc:
            self.recording[confirmed] = False
            self.recording["status_query_error"] = str(exc)

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
        if self._streamer is not None:
            try:
                self._streamer.stop()  # nothing new when paused: that stop was sent
            except (GimbalError, OSError) as exc:
                log.warning("could not send the stop command: %s", exc)
        try:
            self._stop_recording()
        except OSError as exc:  # a bus that went away
            self.recording["error"] = str(exc)
        self._progress.update(self.frames, self.reason, force=True)
        self._progress.close()
        self._finalise("telemetry", self.telemetry.close)  # what was flushed before a failure is kept
        if self.video is not None:
            self._finalise("annotated video", self.video.close)
        if not (self.series.t and self._finalise("plot", self._write_plot)):
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

    def _write_plot(self) -> None:
        s = self.series
        write_timeseries_png(
            self.paths["plot"], s.t,
            [{"yaw": s.yaw_error, "pitch": s.pitch_error}, {"yaw": s.yaw_rate, "pitch": s.pitch_rate}],
            titles=["angular error (target - pointing)", "commanded rates"],
            ylabels=["deg", "deg/s"])

    def write_summary(self, sync: bool = True) -> dict[str, Any]:
        """Write the summary as it stands (atomically; ``sync``: fsync it) and return it."""
        self._last_summary = time.monotonic()
        summary = self._summary()
        write_summary(self.paths["summary"], summary, sync)
        return summary

    def _summary(self) -> dict[str, Any]:
        """The summary as it stands."""
        elapsed = time.monotonic() - self._started
        latencies = self.latencies()
        s = self.series
        return {
            "status": self.reason, "error": self.error,
            "source": self.source.description, "live": self.source.is_live,
            "bus": self.bus_description, "tracker": self.tracker.name, "controller": self.options.controller,
            "attitude_feedback": self.feedback,
            "frames": self.frames, "elapsed_s": elapsed, "fps": self.frames / elapsed if elapsed > 0 else None,
            "frames_dropped": self.source.dropped,
            "frames_expected": None if self.source.is_live else self.source.frame_count,
            "states": dict(self.states), "first_acquired_s": self.first_acquired_s,
            "angular_error_deg": {"mean": s.error_sum / s.error_count if s.error_count else None,
                                  "max": s.error_max, "frames": s.error_count},
            "latency_ms": {k: (v * 1000.0 if isinstance(v, float) else v)
                           for k, v in latency_percentiles(latencies).items()},
            "speed_commands": {**self.speed_stats(),
                               **{k: v for k, v in self.client.stats.items() if k.startswith("stop_")}},
            "recording": self.recording,
            "settings": settings_of(self.controller.config),
            "outputs": {k: str(v) for k, v in self.paths.items()},
        }
