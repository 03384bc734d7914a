"""The figures in ``summary.json`` of a file run: latency in milliseconds (the keep-alive measures
seconds), the frame rate, what a file announces and drops, and the angular error."""
from __future__ import annotations

import json
import math
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import pytest

import pipelines.track_session
from pipelines.outputs.telemetry import read_telemetry
from tests.track.helpers import make_clip, roi_at, run_track


def test_latency_is_in_milliseconds_and_fps_is_frames_over_elapsed(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    real = pipelines.track_session.latency_percentiles
    in_seconds: list[dict[str, Any]] = []

    def kept(latencies: Iterable[float]) -> dict[str, Any]:
        in_seconds.append(real(latencies))
        return in_seconds[-1]

    monkeypatch.setattr(pipelines.track_session, "latency_percentiles", kept)

    def position(i: int) -> tuple[int, int]:
        return 140 + i, 100

    clip = make_clip(tmp_path / "clip.avi", 15, position)
    assert run_track(clip, tmp_path / "out", "--roi", roi_at(position), "--no-video", "--realtime") == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    seconds = in_seconds[-1]  # the final summary's
    assert seconds["count"] > 0 and summary["latency_ms"]["count"] == seconds["count"]
    for key in ("p50", "p95", "p99", "max"):
        assert summary["latency_ms"][key] == pytest.approx(seconds[key] * 1000.0)
    assert summary["fps"] == pytest.approx(summary["frames"] / summary["elapsed_s"])
    assert 0.4 < summary["elapsed_s"] < 30 and summary["frames"] == summary["frames_expected"] == 15
    assert summary["frames_dropped"] == 0 and summary["live"] is False


def test_angular_error_is_over_the_frames_with_a_subject_only(tmp_path: Path) -> None:
    """The frames while the detector confirms the subject have no error: they count in neither
    the mean nor the number of frames it is over."""
    def position(i: int) -> tuple[int, int]:
        return 60 + 4 * i, 100  # moving, for the motion detector

    clip = make_clip(tmp_path / "clip.avi", 20, position)
    assert run_track(clip, tmp_path / "out", "--detect", "motion", "--no-video") == 0
    errors = [math.hypot(*r["error_deg"]) for r in read_telemetry(tmp_path / "out" / "telemetry.jsonl")
              if r["error_deg"] is not None]
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert 0 < len(errors) < summary["frames"] == 20
    assert summary["angular_error_deg"] == pytest.approx(
        {"mean": sum(errors) / len(errors), "max": max(errors), "frames": len(errors)}, rel=1e-12)
