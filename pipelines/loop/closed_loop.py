"""The run behind ``gimbaltrack simulate``: the shared ``Loop`` on a recorded sequence seen through
a virtual camera: view -> tracker -> controller -> GimbalClient -> CAN (python-can ``virtual``) ->
simulated gimbal, whose attitude turns the virtual camera.

Runs in real time (the client's keep-alive and the simulator run on the wall clock). Each frame
is captured (rendered at the simulator's true attitude), handed to the tracker ``latency_s``
later, and the setpoint goes out through the ``SpeedStreamer``; the ground truth in the view
gives the centring error of every frame that has one. A frame without ground truth (a NaN box,
or width or height not above 0, as ``tracker.evaluation.metrics.has_truth``) is left out of the scores and
is no detection for the oracle; the tracker sees its rendered view as any other.
"""
from __future__ import annotations

import time
from collections import deque
from collections.abc import Iterator, Sequence as Seq
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from gimbal.client import GimbalClient
from gimbal.sim import SimConfig, start_in_process
from gimbal.sim.model import GimbalModel
from pipelines.control.controller import ControlConfig, Controller, RateCommand, make_controller
from pipelines.control.gimbal_link import GimbalLink
from pipelines.control.metrics import CentringSample, summarize
from pipelines.loop import Loop, Sink
from pipelines.sources import Frame
from pipelines.sources.virtual_camera import VirtualCamera
from tracker import SubjectTracker, make_tracker
from tracker.detectors import Detection
from tracker.evaluation import first_box
from tracker.evaluation.datasets import Sequence, load_sequence
from tracker.evaluation.metrics import has_truth
from tracker.runtime.boxes import Box, center, start_box
from tracker.runtime.estimate import TargetEstimate, TrackState

if TYPE_CHECKING:
    import can

ORACLE = "oracle"
SIM_CONFIG = SimConfig(yaw_continuous=True)  # the simulated gimbal the loop turns


@dataclass(frozen=True)
class LoopSettings:
    controller: str = "pid"
    tracker: str = ORACLE  # "oracle": the ground-truth box is the detection; else tracker.make_tracker
    hfov_deg: float | None = None  # view field of view; None: crop-equivalent
    out_size: tuple[int, int] = (640, 360)
    latency_s: float = 0.0  # added between capture and tracking
    fps: float = 30.0
    control: ControlConfig = ControlConfig()
    model_dir: Path | None = None  # the tracker's model files (e.g. NanoTrack's), as make_tracker takes them
    max_frames: int | None = None  # stop after this many frames (None: the whole sequence)


@dataclass(frozen=True)
class LoopStep:
    """One frame: its capture time (from the start), centring sample (``None`` without ground
    truth) and the setpoint it produced."""

    t: float
    sample: CentringSample | None
    command: RateCommand


@dataclass
class LoopResult:
    settings: LoopSettings  # as used: the tracker's resolved name, the view's field of view
    steps: list[LoopStep]
    summary: dict[str, float | int | None]
    command_latencies: list[float]  # capture -> first send on the bus, seconds


class OracleTracker:
    """The ground-truth view box as a perfect detection (LOST when its centre is out of view)."""

    def __init__(self, width: int, height: int) -> None:
        self.width, self.height = width, height

    def estimate(self, box: Box | None, timestamp: float, index: int) -> TargetEstimate:
        found = False
        if box is not None:
            cx, cy = center(box)
            found = 0 <= cx < self.width and 0 <= cy < self.height
        return TargetEstimate(box or (0.0, 0.0, 0.0, 0.0), (0.0, 0.0), 1.0 if found else 0.0,
                              TrackState.TRACKING if found else TrackState.LOST, timestamp, index)


class SimulatedSubject:
    """What the loop follows in a simulation (a ``pipelines.loop.Subject``): the oracle's estimate
    of the frame's ground truth, or a real tracker, started on the first view's ground truth (that
    first frame's estimate is the oracle's). The driver sets ``truth`` before each step."""

    candidates: tuple[Detection, ...] = ()

    def __init__(self, oracle: OracleTracker, tracker: SubjectTracker | None) -> None:
        self.oracle = oracle
        self.tracker = tracker
        self.truth: Box | None = None
        self._start: Box | None = None

    @property
    def name(self) -> str:
        return ORACLE if self.tracker is None else self.tracker.name

    def start(self, box: Box) -> None:
        """Start the tracker afresh on ``box`` at the next frame (the oracle needs no start)."""
        if self.tracker is None:
            raise ValueError("the oracle follows the ground truth: it takes no start box")
        self._start = tuple(box)

    def estimate(self, frame: Frame, t: float) -> TargetEstimate:
        oracle = self.oracle.estimate(self.truth, t, frame.index)
        if self.tracker is None:
            return oracle
        if frame.index == 0:
            self.tracker.init(frame.image, self.truth, t)
            return oracle
        if self._start is not None:
            box, self._start = self._start, None
            return self.tracker.init(frame.image, box, t)
        return self.tracker.update(frame.image, t)


@dataclass
class _Captured:
    due: float
    t: float
    index: int
    view: np.ndarray
    box: Box | None
    sample: CentringSample | None


def _sleep_until(t: float) -> None:
    delay = t - time.monotonic()
    if delay > 0:
        time.sleep(delay)


def _truth_in_view(vc: VirtualCamera, source_box: Box, yaw: float, pitch: float,
                   t: float) -> tuple[Box | None, CentringSample | None]:
    """The ground-truth box in the view (``None`` if behind it) and the frame's centring sample at
    ``t``; both ``None`` for a frame without ground truth."""
    if not has_truth(source_box):
        return None, None
    return (vc.box_to_view(source_box, yaw, pitch),
            CentringSample(t, *vc.center_offset(source_box, yaw, pitch)))


def _check_truth(seq: Sequence, tracked: bool) -> None:
    """ValueError when no frame has ground truth, or a ``tracked`` run's first frame has none (the
    tracker starts on it)."""
    if seq.groundtruth is None or not any(has_truth(box) for box in seq.groundtruth):
        raise ValueError(f"{seq.name}: no ground truth, cannot measure centring")
    if tracked:
        first_box(seq)


def start_pointing(vc: VirtualCamera, seq: Sequence, config: SimConfig = SIM_CONFIG) -> SimConfig:
    """``config`` with the gimbal's start pose turned to centre the first ground-truth box in the
    view (pitch held within the simulated gimbal's range), so a subject that starts away from the
    wide frame's centre is in view at the first frame instead of out of it."""
    box = next(box for box in seq.groundtruth if has_truth(box))
    yaw, pitch = vc.source.pixel_to_angles(*center(box))
    pitch_range = GimbalModel(config, now=0.0).axis_range("pitch")
    _, roll, _ = config.initial_joint_deg
    pitch = min(max(pitch, pitch_range.low), pitch_range.high)
    return replace(config, initial_joint_deg=(yaw - config.base_yaw_deg, roll, pitch))


@dataclass
class PreparedLoop:
    """A sequence loaded and checked, its first frame read, and the view, controller and tracker
    made: what a bad sequence or setting fails, it fails in ``prepare_loop``, before anything runs
    (or a front end creates its output folder)."""

    settings: LoopSettings
    seq: Sequence
    frames: Iterator[np.ndarray]  # from the second frame on
    first: np.ndarray
    vc: VirtualCamera
    controller: Controller
    subject: SubjectTracker | None  # None: the oracle
    sim_config: SimConfig  # the simulated gimbal, pointed at the first ground-truth box
    samples: dict[int, CentringSample | None] = field(default_factory=dict)  # by frame index, as the run goes


def prepare_loop(sequence: str | Path, settings: LoopSettings = LoopSettings()) -> PreparedLoop:
    """``sequence`` (a folder or video with ground truth) ready to run; ValueError or
    FileNotFoundError for a bad one."""
    seq = load_sequence(sequence)
    _check_truth(seq, tracked=settings.tracker != ORACLE)
    frames: Iterator[np.ndarray] = seq.frames()
    first = next(frames)
    vc = VirtualCamera((first.shape[1], first.shape[0]), settings.out_size, settings.hfov_deg)
    controller = make_controller(settings.controller, camera=vc.camera, config=settings.control)
    subject = None if settings.tracker == ORACLE else make_tracker(settings.tracker, settings.model_dir)
    sim_config = start_pointing(vc, seq)
    if subject is not None:  # the tracker starts on the first view, taken at the gimbal's start pose
        joint_yaw, _, pitch = sim_config.initial_joint_deg
        view_box = vc.box_to_view(first_box(seq), joint_yaw + sim_config.base_yaw_deg, pitch)
        if view_box is None:
            raise ValueError(f"{seq.name}: the first ground-truth box is behind the view")
        start_box(view_box, *settings.out_size)
    return PreparedLoop(settings, seq, frames, first, vc, controller, subject, sim_config)


def run_closed_loop(sequence: str | Path, settings: LoopSettings = LoopSettings()) -> LoopResult:
    """Run ``sequence`` (a folder or video with ground truth) through the loop; see the module doc."""
    return run_prepared(prepare_loop(sequence, settings))


def run_prepared(loop: PreparedLoop, sinks: Seq[Sink] = (), listeners: Seq[can.Listener] = ()) -> LoopResult:
    """Run a prepared loop; see the module doc. ``sinks`` get every frame's record and view (and
    are closed however the run ends), ``listeners`` every CAN frame both ways (e.g. a CAN log)."""
    settings, seq, frames, first, vc = loop.settings, loop.seq, loop.frames, loop.first, loop.vc
    subject = SimulatedSubject(OracleTracker(vc.camera.width, vc.camera.height), loop.subject)

    host_bus, sim = start_in_process(loop.sim_config)
    steps: list[LoopStep] = []
    try:
        with GimbalClient(host_bus, listeners=list(listeners)) as client:
            link = GimbalLink(client)
            link.start(wait_s=1.0)
            closed = Loop(subject, loop.controller, link)
            for sink in sinks:
                closed.attach(sink)
            pending: deque[_Captured] = deque()
            t0 = time.monotonic() + 0.05
            truth = iter(seq.groundtruth)

            def process(item: _Captured) -> None:
                subject.truth = item.box
                loop.samples[item.index] = item.sample
                record = closed.step(Frame(item.view, item.t, item.index), item.t)
                steps.append(LoopStep(item.t - t0, item.sample, record.command))

            frame: np.ndarray | None = first
            index = 0
            while frame is not None or pending:
                t_next = t0 + index / settings.fps if frame is not None else float("inf")
                if pending and pending[0].due <= t_next:
                    _sleep_until(pending[0].due)
                    process(pending.popleft())
                    continue
                _sleep_until(t_next)
                t_cap = time.monotonic()
                yaw, _, pitch = sim.state().attitude
                view = vc.render(frame, yaw, pitch)
                box, sample = _truth_in_view(vc, next(truth), yaw, pitch, t_cap - t0)
                pending.append(_Captured(t_cap + settings.latency_s, t_cap, index, view, box, sample))
                index += 1
                frame = next(frames, None) if settings.max_frames is None or index < settings.max_frames else None
            link.stop()
            latencies = link.latencies()
    finally:
        sim.stop()
        host_bus.shutdown()
        for sink in sinks:
            sink.close()
    used = replace(settings, tracker=subject.name, hfov_deg=vc.camera.hfov_deg)
    return LoopResult(used, steps, summarize([s.sample for s in steps]), latencies)
