"""What ``gimbaltrack track`` prints at the end of a run: ``--json`` the summary itself, the text
report a latency line only when there is a latency, and no note about ``--realtime``/``--fps`` for
a file, which takes them."""
from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import pytest

import pipelines.track_session
from tests.track.helpers import drifting, make_clip, roi_at, run_track


def test_json_prints_the_summary_as_written(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    clip = make_clip(tmp_path / "clip.avi", 10, drifting)
    out = tmp_path / "out"
    assert run_track(clip, out, "--roi", roi_at(drifting), "--no-video", "--json", "--realtime", "--fps", "60") == 0
    printed = capsys.readouterr()
    assert json.loads(printed.out) == json.loads((out / "summary.json").read_text())
    assert "note" not in printed.err  # a file plays at --fps in real time: nothing is ignored


def test_a_run_without_a_latency_reports_none(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    real = pipelines.track_session.latency_percentiles

    def none_measured(latencies: Iterable[float]) -> dict[str, Any]:
        return real([])

    monkeypatch.setattr(pipelines.track_session, "latency_percentiles", none_measured)
    clip = make_clip(tmp_path / "clip.avi", 5, drifting)
    assert run_track(clip, tmp_path / "out", "--roi", roi_at(drifting), "--no-video") == 0
    report = capsys.readouterr().out
    assert report.startswith("end of source: 5 frames") and "command latency" not in report
