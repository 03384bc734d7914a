"""What an operator does reaches a running ``track`` through ``loop.submit`` from another thread
(the way a console will): the stop ends the run like its end, with the gimbal told to stop."""
from __future__ import annotations

import json
import threading
from pathlib import Path

import pytest

from pipelines.loop.track_session import TrackSession
from tests.track.helpers import DEMO, DEMO_ROI, assert_stopped_at_end, decoded, run_track


def test_an_operator_stop_from_another_thread_ends_the_run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    real = TrackSession.step
    submitted: list = []

    def step(self: TrackSession, frame):
        record = real(self, frame)
        if record.index == 20:  # an operator elsewhere: a thread of its own hands the loop the stop
            operator = threading.Thread(target=lambda: submitted.append(self.loop.submit(self.loop.stop)))
            operator.start()
            operator.join()
        return record

    monkeypatch.setattr(TrackSession, "step", step)
    out = tmp_path / "out"
    assert run_track(DEMO, out, "--roi", DEMO_ROI, "--no-video") == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "stopped by the operator"
    assert summary["frames"] == 22  # the stop ran at the start of the next frame, which was finished
    assert submitted[0].done() and submitted[0].exception() is None
    assert_stopped_at_end(decoded(out / "can.log"))


def test_an_operator_start_box_restarts_the_tracker(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    real = TrackSession.step
    boxes: list = []

    def step(self: TrackSession, frame):
        if frame.index == 10:
            self.loop.submit(lambda: self.loop.start_tracking((40, 40, 30, 30)))
        record = real(self, frame)
        boxes.append(None if record.estimate is None else record.estimate.box)
        return record

    monkeypatch.setattr(TrackSession, "step", step)
    assert run_track(DEMO, tmp_path / "out", "--roi", DEMO_ROI, "--no-video", "--max-frames", "12") == 0
    assert tuple(boxes[10]) == (40, 40, 30, 30) and tuple(boxes[9]) != (40, 40, 30, 30)
