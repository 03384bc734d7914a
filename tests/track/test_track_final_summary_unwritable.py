"""The last rewrite of ``summary.json`` failing (a full disk) after a run that went well: a one-line
error and exit 1, the gimbal stopped first, and the previous rewrite left in place."""
from __future__ import annotations

import errno
import json
from pathlib import Path
from typing import Any

import pytest

import pipelines.track_session
from tests.track.helpers import assert_stopped_at_end, decoded, drifting, make_clip, roi_at, run_track


def test_a_final_summary_that_cannot_be_written_is_one_line_and_exit_1(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    real = pipelines.track_session.write_summary

    def full_at_the_end(path: Path, summary: dict[str, Any], sync: bool = True) -> None:
        if sync:  # the final rewrite; those during the run pass sync=False
            raise OSError(errno.ENOSPC, "No space left on device")
        real(path, summary, sync)

    monkeypatch.setattr(pipelines.track_session, "write_summary", full_at_the_end)

    clip = make_clip(tmp_path / "clip.avi", 12, drifting)
    out = tmp_path / "out"
    assert run_track(clip, out, "--roi", roi_at(drifting), "--no-video") == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("gimbaltrack track: error:")
    assert "summary: No space left on device" in err and "the gimbal was told to stop" in err
    assert json.loads((out / "summary.json").read_text())["status"] == "running"  # the last rewrite that fitted
    assert_stopped_at_end(decoded(out / "can.log"))
