"""The telemetry of a file run, line by line: the documented keys (docs/outputs.md), where each frame
sits in the recording (``t_video``), nothing dropped, and rates in the project's sign convention."""
from __future__ import annotations

from pathlib import Path

import pytest

from pipelines.outputs.telemetry import read_telemetry
from tests.track.helpers import decoded, make_clip, roi_at, run_track, speed_commands

KEYS = {"frame", "t", "t_video", "t_run", "box", "velocity", "confidence", "state", "error_deg", "rate_dps",
        "mode", "attitude_deg", "attitude_t", "dropped"}


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
