"""``gimbaltrack track udp://...`` on a real live stream: ffmpeg plays the demo clip in real time as
MPEG-TS over UDP; track follows it against the built-in simulator and reports its latency."""
from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

import pipelines.cli.track_cmd  # noqa: F401 (loaded before the stream starts: the 7 s stream is for tracking, not start-up)
from pipelines.outputs.telemetry import read_telemetry
from tests.support import ROOT, free_udp_port, require_ffmpeg
from tests.track.helpers import DEMO, assert_stopped_at_end, decoded, run_track, speed_commands

FRAMES = 90  # 3 s of the 30 fps stream


def _ffmpeg() -> str:
    return require_ffmpeg("a live UDP stream")


def test_tracks_a_live_udp_stream(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    port = free_udp_port()
    url = f"udp://127.0.0.1:{port}"
    streamer = subprocess.Popen(
        [_ffmpeg(), "-loglevel", "error", "-re", "-i", str(DEMO), "-t", "7", "-c:v", "mpeg2video", "-q:v", "4",
         "-f", "mpegts", f"{url}?pkt_size=1316"], cwd=ROOT, stdin=subprocess.DEVNULL)
    out = tmp_path / "out"
    try:
        code = run_track(url, out, "--detect", "motion", "--max-frames", str(FRAMES), "--json", "--realtime")
    finally:
        streamer.kill()
        streamer.wait()
    err = capsys.readouterr().err
    assert code == 0, err
    assert "note: ignoring --realtime for a live source" in err
    summary = json.loads((out / "summary.json").read_text())
    print("live:", json.dumps({k: summary[k] for k in ("fps", "frames_dropped", "latency_ms", "states")}))
    assert summary["live"] is True and summary["attitude_feedback"] is True
    assert summary["status"] == "max frames reached" and summary["frames"] == FRAMES
    assert summary["states"].get("tracking", 0) > FRAMES // 2
    assert summary["latency_ms"]["count"] > 10 and 0 < summary["latency_ms"]["p50"] < 200
    telemetry = read_telemetry(out / "telemetry.jsonl")
    assert len(telemetry) == FRAMES and telemetry[-1]["attitude_deg"] is not None
    assert telemetry[-1]["dropped"] == summary["frames_dropped"]
    records = decoded(out / "can.log")
    assert any(not c.zero for c in speed_commands(records))
    assert_stopped_at_end(records)
