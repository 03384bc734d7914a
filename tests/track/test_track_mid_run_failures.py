"""``gimbaltrack track`` when the source fails or the code crashes part-way through a run: the
session itself stops the gimbal (zero, then release) and the summary says how the run ended,
with every frame so far in the telemetry."""
from __future__ import annotations

import errno
import json
from pathlib import Path
from typing import Any

import cv2
import pytest

from pipelines.outputs.telemetry import TelemetryWriter, read_telemetry
from pipelines.acquire import AcquiringSubject
from tests.track.helpers import assert_stopped_at_end, decoded, drifting, make_clip, roi_at, run_track

FRAMES = 20


def _assert_stopped_by_the_session(out: Path, status: str, frames: int) -> dict[str, Any]:
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == status and summary["frames"] == frames
    assert len(read_telemetry(out / "telemetry.jsonl")) == frames
    sends = summary["speed_commands"]
    assert sends["stop_zero_sent"] == sends["stop_release_sent"] == 1
    assert_stopped_at_end(decoded(out / "can.log"))
    return summary


def test_a_source_failing_mid_run_stops_the_gimbal_and_exits_1(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    video = cv2.VideoCapture(str(make_clip(tmp_path / "clip.avi", FRAMES, drifting)))
    folder = tmp_path / "frames"
    folder.mkdir()
    for i in range(FRAMES):
        ok, image = video.read()
        assert ok
        if i == 12:  # one image of another size: the folder source fails there
            image = cv2.resize(image, (160, 120))
        cv2.imwrite(str(folder / f"{i:03d}.png"), image)
    out = tmp_path / "out"
    assert run_track(folder, out, "--roi", roi_at(drifting), "--no-video") == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("gimbaltrack track: error:")
    assert "012.png" in err and "outputs so far are in" in err
    summary = _assert_stopped_by_the_session(out, "source failed", 12)
    assert "one frame size" in summary["error"]


def test_a_crash_mid_run_stops_the_gimbal_and_keeps_the_outputs(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    real = AcquiringSubject.estimate
    calls: list[int] = []

    def crash_on_the_eighth(self: AcquiringSubject, *args: Any) -> Any:
        calls.append(1)
        if len(calls) == 8:
            raise RuntimeError("a bug")
        return real(self, *args)

    monkeypatch.setattr(AcquiringSubject, "estimate", crash_on_the_eighth)
    clip = make_clip(tmp_path / "clip.avi", FRAMES, drifting)
    out = tmp_path / "out"
    with pytest.raises(RuntimeError, match="a bug"):  # a bug shows its traceback
        run_track(clip, out, "--roi", roi_at(drifting))
    summary = _assert_stopped_by_the_session(out, "failed", 7)
    assert summary["error"] == "RuntimeError('a bug')"
    assert (out / "plot.png").exists()


def test_a_telemetry_line_that_cannot_be_written_is_not_counted(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The disk fills up at the eighth frame's telemetry line: the summary's ``frames`` (and its
    states) count the seven frames the telemetry holds, not the eighth, whose line is missing."""
    real = TelemetryWriter.write
    calls: list[int] = []

    def full_at_the_eighth(self: TelemetryWriter, record: Any) -> None:
        calls.append(1)
        if len(calls) == 8:
            raise OSError(errno.ENOSPC, "No space left on device")
        real(self, record)

    monkeypatch.setattr(TelemetryWriter, "write", full_at_the_eighth)
    out = tmp_path / "out"
    assert run_track(make_clip(tmp_path / "clip.avi", FRAMES, drifting), out,
                     "--roi", roi_at(drifting), "--no-video") == 1
    summary = _assert_stopped_by_the_session(out, "output failed", 7)
    assert sum(summary["states"].values()) == 7 and summary["angular_error_deg"]["frames"] <= 7
