"""``summary.json`` during a run: written from the first frame on (a run killed outright still has
one), cheaply (no fsync) while running, and synced once at the end."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import pipelines.track_session
from tests.track.helpers import make_clip, roi_at, run_track


def test_the_summary_is_written_while_running_and_synced_at_the_end(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    real = pipelines.track_session.write_summary
    written: list[tuple[str, int, bool]] = []

    def recorded(path: Path, summary: dict[str, Any], sync: bool = True) -> None:
        written.append((summary["status"], summary["frames"], sync))
        real(path, summary, sync)

    monkeypatch.setattr(pipelines.track_session, "write_summary", recorded)

    def position(i: int) -> tuple[int, int]:
        return 140 + i, 100

    clip = make_clip(tmp_path / "clip.avi", 12, position)
    assert run_track(clip, tmp_path / "out", "--roi", roi_at(position), "--no-video", "--max-frames", "10") == 0
    assert written[0] == ("running", 1, False)  # the first frame's, not only the final one
    assert all(not sync for status, _, sync in written[:-1])
    assert written[-1] == ("max frames reached", 10, True)
