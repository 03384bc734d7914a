"""``--record``: the camera record commands around a run, when the camera refuses the start, and the stop that follows the gimbal's."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from gimbal.client import GimbalClient, SPEED_RELEASE
from gimbal.errors import ReturnCodeError
from gimbal.messages.camera import CameraActionCode
from pipelines.outputs.telemetry import read_telemetry
from tests.track.helpers import (
    assert_stopped_at_end, decoded, drifting, host_commands, make_clip, roi_at, run_track,
)





# ``--record`` when the camera refuses the record start: the run goes on, the summary says the
# recording never started and why, and no record stop is sent for it.
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


# ``--record``'s stop at the end of a run: it follows the gimbal's stop (the last speed command on
# the bus is the release), a stop the camera does not confirm is said so, and one failing with the
# bus itself (``OSError``, an adapter unplugged) still lets the outputs be finalised, the summary
# saying what failed.
def test_the_record_stop_follows_the_gimbal_stop(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    clip = make_clip(tmp_path / "clip.avi", 12, drifting)
    out = tmp_path / "out"
    assert run_track(clip, out, "--roi", roi_at(drifting), "--no-video", "--record") == 0
    assert "recording: started (confirmed), stopped (confirmed)" in capsys.readouterr().out
    sent = host_commands(decoded(out / "can.log"))
    names = [r["name"] for r in sent]
    release = max(i for i, r in enumerate(sent)
                  if r["name"] == "speed_control" and r["fields"]["ctrl_byte"] == SPEED_RELEASE)
    stop = names.index("camera_action", names.index("camera_action") + 1)
    assert sent[stop]["fields"]["action"] == CameraActionCode.STOP_RECORDING
    assert release < stop and "speed_control" not in names[stop:]


def test_a_camera_still_recording_after_the_stop_is_reported(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(GimbalClient, "camera_status", lambda self: True)  # it never stops
    clip = make_clip(tmp_path / "clip.avi", 12, drifting)
    out = tmp_path / "out"
    assert run_track(clip, out, "--roi", roi_at(drifting), "--no-video", "--record") == 0
    assert "recording: started (confirmed), stop NOT confirmed" in capsys.readouterr().out
    recording = json.loads((out / "summary.json").read_text())["recording"]
    assert recording["stopped"] is True and recording["stop_confirmed"] is False


def test_a_record_stop_failing_on_the_bus_still_finishes_the_run(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def unplugged(self: GimbalClient) -> None:
        raise OSError("Network is down")

    monkeypatch.setattr(GimbalClient, "stop_recording", unplugged)
    clip = make_clip(tmp_path / "clip.avi", 12, drifting)
    out = tmp_path / "out"
    assert run_track(clip, out, "--roi", roi_at(drifting), "--record") == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "end of source" and summary["frames"] == 12
    assert summary["recording"]["started"] is True and summary["recording"]["error"] == "Network is down"
    assert len(read_telemetry(out / "telemetry.jsonl")) == 12 and (out / "plot.png").exists()
    assert_stopped_at_end(decoded(out / "can.log"))
