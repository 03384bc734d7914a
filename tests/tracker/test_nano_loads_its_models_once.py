"""``nano`` (OpenCV's TrackerNano, which takes model paths only) reads each model file once per
backend: not once to check the files and again for the tracker, nor again on every restart."""
from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import Any

import cv2
import pytest

from tests import fake_onnx
from tracker.backends import make_backend
from tracker.evaluation.synthetic import render_sequence


def test_each_model_file_is_loaded_once_however_often_the_backend_restarts(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    models = fake_onnx.write_nanotrack_files(tmp_path, fake_onnx.backbone_bytes(), fake_onnx.head_bytes())
    loads: Counter[str] = Counter()
    read_net, create = cv2.dnn.readNet, cv2.TrackerNano_create

    def counted_read(path: str, *args: Any) -> cv2.dnn.Net:
        loads[Path(path).name] += 1
        return read_net(path, *args)

    def counted_create(params: cv2.TrackerNano_Params) -> cv2.TrackerNano:
        loads.update([Path(params.backbone).name, Path(params.neckhead).name])
        return create(params)

    monkeypatch.setattr(cv2.dnn, "readNet", counted_read)
    monkeypatch.setattr(cv2, "TrackerNano_create", counted_create)
    backend = make_backend("nano", models)
    frame = render_sequence(frames=1, seed=1).frames[0]
    for _ in range(3):  # the start and two restarts (re-acquisitions)
        backend.init(frame, (100.0, 80.0, 40.0, 40.0))
        backend.update(frame)
    assert loads == {"nanotrack_backbone_sim.onnx": 1, "nanotrack_head_sim.onnx": 1}


def test_a_restart_tracks_as_a_fresh_backend_does(shared_data: Path) -> None:
    """The one TrackerNano is initialised again on a restart: nothing of the earlier run stays."""
    seq = render_sequence(frames=12, speed=4.0, seed=7)
    used = make_backend("nano", shared_data / "models")
    used.init(seq.frames[0], seq.boxes[0])
    for frame in seq.frames[1:6]:
        used.update(frame)
    fresh = make_backend("nano", shared_data / "models")
    for backend in (used, fresh):
        backend.init(seq.frames[6], seq.boxes[6])
    assert [used.update(f) for f in seq.frames[7:]] == [fresh.update(f) for f in seq.frames[7:]]


def test_files_that_pass_the_check_but_not_trackernano_are_a_value_error(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """E.g. an OpenCV whose TrackerNano cannot run them: said when the backend is made, not mid-run."""
    models = fake_onnx.write_nanotrack_files(tmp_path, fake_onnx.backbone_bytes(), fake_onnx.head_bytes())

    def refuse(params: cv2.TrackerNano_Params) -> cv2.TrackerNano:
        raise cv2.error("OpenCV(4.x) tracker_nano.cpp:1: error: (-215:Assertion failed) something")

    monkeypatch.setattr(cv2, "TrackerNano_create", refuse)
    with pytest.raises(ValueError, match=r"^OpenCV's TrackerNano cannot use .*nanotrack_backbone_sim.onnx "
                                         r"and .*nanotrack_head_sim.onnx: .*Assertion failed\) something$"):
        make_backend("nano", models)
