"""An output that cannot even be opened (here the telemetry's name taken by a folder) is a one-line
error and exit 2 before the gimbal is ever moved, not a traceback."""
from __future__ import annotations

from pathlib import Path

import pytest

from tests.track.helpers import decoded, make_clip, roi_at, run_track, speed_commands


def test_an_output_that_cannot_be_opened_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    def position(i: int) -> tuple[int, int]:
        return 140 + i, 100

    clip = make_clip(tmp_path / "clip.avi", 5, position)
    out = tmp_path / "out"
    (out / "telemetry.jsonl").mkdir(parents=True)
    assert run_track(clip, out, "--roi", roi_at(position), "--no-video") == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("gimbaltrack track: error:")
    assert "telemetry.jsonl" in err and "Traceback" not in err
    assert speed_commands(decoded(out / "can.log")) == []
