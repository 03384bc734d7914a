"""What ``gimbaltrack track`` writes and prints: the summary (figures, rewrites during the run), the telemetry columns and the end-of-run report."""
from __future__ import annotations

import json
import math
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import pytest

import pipelines.loop.track_session
from pipelines.outputs.telemetry import read_telemetry
from tests.track.helpers import decoded, drifting, make_clip, roi_at, run_track, speed_commands





# The figures in ``summary.json`` of a file run: latency in milliseconds (the keep-alive measures
# seconds), the frame rate, what a file announces and drops, and the angular error.
def test_latency_is_in_milliseconds_and_fps_is_frames_over_elapsed(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    real = pipelines.loop.track_session.latency_percentiles
    in_seconds: list[dict[str, Any]] = []

    def kept(latencies: Iterable[float]) -> dict[str, Any]:
        in_seconds.append(real(latencies))
        return in_seconds[-1]

    monkeypatch.setattr(pipelines.loop.track_session, "latency_percentiles", kept)

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


# ``summary.json`` during a run: written from the first frame on (a run killed outright still has
# one), cheaply (no fsync) while running, and synced once at the end.
def test_the_summary_is_written_while_running_and_synced_at_the_end(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    real = pipelines.loop.track_session.write_summary
    written: list[tuple[str, int, bool]] = []

    def recorded(path: Path, summary: dict[str, Any], sync: bool = True) -> None:
        written.append((summary["status"], summary["frames"], sync))
        real(path, summary, sync)

    monkeypatch.setattr(pipelines.loop.track_session, "write_summary", recorded)

    def position(i: int) -> tuple[int, int]:
        return 140 + i, 100

    clip = make_clip(tmp_path / "clip.avi", 12, position)
    assert run_track(clip, tmp_path / "out", "--roi", roi_at(position), "--no-video", "--max-frames", "10") == 0
    assert written[0] == ("running", 1, False)  # the first frame's, not only the final one
    assert all(not sync for status, _, sync in written[:-1])
    assert written[-1] == ("max frames reached", 10, True)


# The telemetry of a file run, line by line: the documented keys (docs/outputs.md), where each frame
# sits in the recording (``t_video``), nothing dropped, and rates in the project's sign convention.
KEYS = {"frame", "t", "t_video", "t_run", "box", "velocity", "confidence", "state", "error_deg", "rate_dps",
        "mode", "attitude_deg", "attitude_t", "dropped", "bus", "other_hosts"}


def test_a_file_runs_telemetry_has_every_column_and_the_recordings_time(tmp_path: Path) -> None:
    def position(i: int) -> tuple[int, int]:
        return 140 + i, 100

    clip = make_clip(tmp_path / "clip.avi", 12, position, fps=25.0)
    assert run_track(clip, tmp_path / "out", "--roi", roi_at(position), "--no-video") == 0
    telemetry = read_telemetry(tmp_path / "out" / "telemetry.jsonl")
    assert [r["frame"] for r in telemetry] == list(range(12))
    assert all(r.keys() == KEYS for r in telemetry)
    assert [r["t_video"] for r in telemetry] == pytest.approx([i / 25.0 for i in range(12)])
    assert all(r["dropped"] == 0 for r in telemetry)
    for earlier, later in zip(telemetry, telemetry[1:]):
        assert earlier["t"] <= later["t"] and earlier["t_run"] <= later["t_run"]


def test_rates_stay_in_the_projects_convention_when_the_bus_is_inverted(tmp_path: Path) -> None:
    """``--invert-yaw/--invert-pitch`` flip the commands on the bus only (docs/outputs.md)."""
    def position(i: int) -> tuple[int, int]:
        return 230 + i % 3, 170  # right of and below the centre: yaw +, pitch -

    clip = make_clip(tmp_path / "clip.avi", 20, position)
    out = tmp_path / "out"
    assert run_track(clip, out, "--roi", roi_at(position), "--no-video", "--invert-yaw", "--invert-pitch") == 0
    rates = [r["rate_dps"] for r in read_telemetry(out / "telemetry.jsonl") if r["rate_dps"] != [0.0, 0.0]]
    assert len(rates) > 5 and all(yaw > 0 and pitch < 0 for yaw, pitch in rates)
    moving = [c for c in speed_commands(decoded(out / "can.log")) if not c.zero]
    assert moving and all(c.yaw < 0 and c.pitch > 0 for c in moving)


# What ``gimbaltrack track`` prints at the end of a run: ``--json`` the summary itself, the text
# report a latency line only when there is a latency, and no note about ``--realtime``/``--fps`` for
# a file, which takes them.
def test_json_prints_the_summary_as_written(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    clip = make_clip(tmp_path / "clip.avi", 10, drifting)
    out = tmp_path / "out"
    assert run_track(clip, out, "--roi", roi_at(drifting), "--no-video", "--json", "--realtime", "--fps", "60") == 0
    printed = capsys.readouterr()
    assert json.loads(printed.out) == json.loads((out / "summary.json").read_text())
    assert "note" not in printed.err  # a file plays at --fps in real time: nothing is ignored


def test_a_run_without_a_latency_reports_none(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    real = pipelines.loop.track_session.latency_percentiles

    def none_measured(latencies: Iterable[float]) -> dict[str, Any]:
        return real([])

    monkeypatch.setattr(pipelines.loop.track_session, "latency_percentiles", none_measured)
    clip = make_clip(tmp_path / "clip.avi", 5, drifting)
    assert run_track(clip, tmp_path / "out", "--roi", roi_at(drifting), "--no-video") == 0
    report = capsys.readouterr().out
    assert report.startswith("end of source: 5 frames") and "command latency" not in report
