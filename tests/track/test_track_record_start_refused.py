"""``--record`` when the camera refuses the record start: the run goes on, the summary says the
recording never started and why, and no record stop is sent for it."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from gimbal.client import GimbalClient
from gimbal.errors import ReturnCodeError
from tests.track.helpers import assert_stopped_at_end, decoded, drifting, host_commands, make_clip, roi_at, run_track


def test_a_refused_record_start_is_reported_and_never_stopped(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(self: GimbalClient) -> None:
        raise ReturnCodeError("camera_action", 0x02)

    monkeypatch.setattr(GimbalClient, "start_recording", refuse)

    clip = make_clip(tmp_path / "clip.avi", 15, drifting)
    out = tmp_path / "out"
    assert run_track(clip, out, "--roi", roi_at(drifting), "--no-video", "--record") == 0
    recording = json.loads((out / "summary.json").read_text())["recording"]
    assert recording == {"requested": True, "started": False, "error": str(ReturnCodeError("camera_action", 0x02))}
    assert f"recording: not started ({recording['error']})" in capsys.readouterr().out
    records = decoded(out / "can.log")
    assert not [r for r in host_commands(records) if r["name"] == "camera_action"]
    assert_stopped_at_end(records)
