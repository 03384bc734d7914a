"""The shared loop: one step per frame, records to the sinks in order, and work handed over from
other threads run on the loop's thread at the start of the next step."""
from __future__ import annotations

import math
import threading
from concurrent.futures import CancelledError

import numpy as np
import pytest

from pipelines.control.controller import RateCommand
from pipelines.loop import OPERATOR_STOP, FrameRecord, Loop, Recorder
from pipelines.sources import Frame
from tracker.runtime.estimate import TargetEstimate, TrackState


class Subject:
    name = "fake"

    def __init__(self) -> None:
        self.candidates = ()
        self.started: list = []
        self.threads: list = []

    def start(self, box) -> None:
        self.started.append(tuple(box))

    def estimate(self, frame, t):
        self.threads.append(threading.current_thread())
        if t < 1.0:
            return None
        return TargetEstimate((10.0, 10.0, 4.0, 4.0), (0.0, 0.0), 0.9, TrackState.TRACKING, t, 0)


class Controller:
    def __init__(self) -> None:
        self.seen: list = []

    def update(self, estimate, attitude, now):
        self.seen.append((estimate, attitude))
        if estimate is None:
            return RateCommand(0.0, 0.0)
        return RateCommand(3.0, -2.0, mode="track", yaw_error_deg=3.0, pitch_error_deg=4.0)


class Link:
    def __init__(self) -> None:
        self.sent: list = []

    def attitude_at(self, t):
        return (5.0, 6.0)

    def latest(self):
        return None

    def send(self, command, stamp=None):
        self.sent.append((command.yaw_dps, command.pitch_dps, stamp))

    def health(self):
        return None

    def other_hosts(self):
        return None


class Sink:
    def __init__(self, name: str, seen: list) -> None:
        self.name, self.seen = name, seen

    def on_frame(self, record, frame) -> None:
        self.seen.append((self.name, record.index))

    def close(self) -> None:
        pass


class Client:
    def __init__(self) -> None:
        self.calls: list = []

    def start_recording(self) -> None:
        self.calls.append("start")

    def stop_recording(self) -> None:
        self.calls.append("stop")

    def camera_status(self) -> bool:
        return self.calls[-1] == "start"


def frame(index: int) -> Frame:
    return Frame(np.zeros((8, 8, 3), np.uint8), float(index), index)


def make_loop(**kwargs) -> tuple[Loop, Subject, Controller, Link]:
    subject, controller, link = Subject(), Controller(), Link()
    clock = iter(range(100, 1000)).__next__
    return Loop(subject, controller, link, clock=lambda: float(clock()), **kwargs), subject, controller, link


def test_a_step_tracks_controls_sends_and_records() -> None:
    loop, _, controller, link = make_loop(video_fps=10.0, dropped=lambda: 3)
    first, second = loop.step(frame(0), 0.5), loop.step(frame(1), 1.5)
    assert (first.state, first.found, first.error_deg, first.angular_error_deg) == ("acquiring", False, None, None)
    assert second.state == "tracking" and second.error_deg == (3.0, 4.0) and second.angular_error_deg == 5.0
    assert (second.t, second.t_video, second.dropped, second.recording) == (1.5, 0.1, 3, False)
    assert link.sent == [(0.0, 0.0, 0.5), (3.0, -2.0, 1.5)]  # stamped with the frames' capture times
    assert [attitude for _, attitude in controller.seen] == [(5.0, 6.0), (5.0, 6.0)]
    assert loop.first_acquired_s is not None and loop.first_acquired_s > 0


def test_without_feedback_the_attitude_is_fixed() -> None:
    loop, _, controller, _ = make_loop(feedback=False)
    loop.step(frame(0), 1.0)
    assert controller.seen[0][1] == (0.0, 0.0)


def test_sinks_see_every_record_in_the_order_attached() -> None:
    loop, *_ = make_loop()
    seen: list = []
    loop.attach(Sink("telemetry", seen))
    loop.attach(Sink("video", seen))
    record = loop.step(frame(7), 1.0)
    assert isinstance(record, FrameRecord) and seen == [("telemetry", 7), ("video", 7)]


def test_work_from_another_thread_runs_on_the_loop_thread_at_the_next_step() -> None:
    loop, subject, *_ = make_loop()
    ran: list = []

    def submit() -> None:
        ran.append(loop.submit(lambda: ran.append(threading.current_thread()) or "done"))

    worker = threading.Thread(target=submit)
    worker.start()
    worker.join()
    future = ran[0]
    assert not future.done()  # nothing runs until the loop steps
    loop.step(frame(0), 1.0)
    assert future.result(timeout=1) == "done" and ran[1] is threading.main_thread()
    assert subject.threads == [threading.main_thread()]


def test_a_failing_command_reaches_its_submitter_not_the_loop() -> None:
    loop, *_ = make_loop()
    failing = loop.submit(lambda: 1 / 0)
    later = loop.submit(lambda: "still runs")
    loop.step(frame(0), 1.0)
    with pytest.raises(ZeroDivisionError):
        failing.result(timeout=1)
    assert later.result(timeout=1) == "still runs"


def test_work_left_when_the_run_ends_is_cancelled() -> None:
    loop, *_ = make_loop()
    future = loop.submit(lambda: "never")
    loop.cancel_submitted()
    with pytest.raises(CancelledError):
        future.result(timeout=1)


def test_operator_commands() -> None:
    client = Client()
    loop, subject, *_ = make_loop(recorder=Recorder(client))
    loop.submit(lambda: loop.start_tracking((1, 2, 3, 4)))
    loop.submit(loop.start_recording)
    record = loop.step(frame(0), 1.0)
    assert subject.started == [(1, 2, 3, 4)] and client.calls == ["start"] and record.recording
    assert loop.recorder.status == {"requested": False, "started": True, "start_confirmed": True}
    loop.submit(loop.stop_recording)
    loop.submit(loop.stop)
    record = loop.step(frame(1), 2.0)
    assert client.calls == ["start", "stop"] and not record.recording
    assert loop.stop_reason == OPERATOR_STOP


def test_recording_needs_a_camera() -> None:
    loop, *_ = make_loop()
    future = loop.submit(loop.start_recording)
    loop.step(frame(0), 1.0)
    with pytest.raises(RuntimeError, match="no camera"):
        future.result(timeout=1)


def test_a_requested_recording_starts_on_the_first_acquisition_only() -> None:
    client = Client()
    loop, *_ = make_loop(recorder=Recorder(client, requested=True))
    loop.step(frame(0), 0.5)  # acquiring
    assert client.calls == []
    loop.step(frame(1), 1.5)
    loop.step(frame(2), 2.5)
    assert client.calls == ["start"]
    loop.recorder.finish()
    assert client.calls == ["start", "stop"] and not math.isnan(loop.first_acquired_s)
