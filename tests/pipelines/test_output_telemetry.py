"""Telemetry JSONL: one flushed line per record, readable after a crash."""
from __future__ import annotations

import json
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from pipelines.outputs.telemetry import TelemetryWriter, estimate_fields, read_telemetry
from tracker.runtime.estimate import TargetEstimate, TrackState


def test_lines_survive_a_crash_before_close(tmp_path: Path, run_and_crash: Callable[[str], None]) -> None:
    path = tmp_path / "telemetry.jsonl"
    run_and_crash(f"""
        from pipelines.outputs.telemetry import TelemetryWriter
        writer = TelemetryWriter({str(path)!r})
        for i in range(5):
            writer.write({{"frame": i, "t": i / 30}})
    """)
    assert read_telemetry(path) == [{"frame": i, "t": i / 30} for i in range(5)]


def test_each_record_is_on_disk_as_soon_as_written(tmp_path: Path) -> None:
    path = tmp_path / "telemetry.jsonl"
    writer = TelemetryWriter(path)
    writer.write({"frame": 0})
    assert path.read_text() == '{"frame":0}\n'
    writer.write({"frame": 1})
    assert len(path.read_text().splitlines()) == 2 and writer.records == 2
    writer.close()


def test_values_are_made_json_ready(tmp_path: Path) -> None:
    path = tmp_path / "telemetry.jsonl"
    with TelemetryWriter(path) as writer:
        writer.write({"box": (1, 2.5, np.float32(3.0), np.int64(4)), "state": TrackState.SEARCHING,
                      "error_deg": np.array([0.5, math.nan]), "ok": np.bool_(True), "attitude_deg": None})
    assert json.loads(path.read_text()) == {"box": [1, 2.5, 3.0, 4], "state": "searching",
                                            "error_deg": [0.5, None], "ok": True, "attitude_deg": None}


def test_unknown_types_are_refused(tmp_path: Path) -> None:
    with TelemetryWriter(tmp_path / "t.jsonl") as writer, pytest.raises(TypeError, match="object"):
        writer.write({"bad": object()})


def test_append_mode_keeps_earlier_lines(tmp_path: Path) -> None:
    path = tmp_path / "t.jsonl"
    with TelemetryWriter(path) as writer:
        writer.write({"frame": 0})
    with TelemetryWriter(path, append=True) as writer:
        writer.write({"frame": 1})
    assert [r["frame"] for r in read_telemetry(path)] == [0, 1]


def test_reader_ignores_only_a_torn_last_line(tmp_path: Path) -> None:
    path = tmp_path / "t.jsonl"
    path.write_text('{"frame":0}\n{"frame":1}\n{"fra')
    assert read_telemetry(path) == [{"frame": 0}, {"frame": 1}]
    path.write_text('{"frame":0}\n{"fra\n{"frame":2}\n')
    with pytest.raises(ValueError, match=":2: not a JSON object"):
        read_telemetry(path)


def test_estimate_fields() -> None:
    estimate = TargetEstimate((10.0, 20.0, 30.0, 40.0), (1.5, -2.0), 0.75, TrackState.TRACKING, 1.25, 37)
    assert estimate_fields(estimate) == {"box": [10.0, 20.0, 30.0, 40.0],
                                         "velocity": [1.5, -2.0], "confidence": 0.75, "state": "tracking"}


# A telemetry line that cannot be written (a full disk) raises an ``OSError`` naming the file, so
# the one-line error of the run says which output failed.
@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_a_failed_write_names_the_telemetry_file(tmp_path: Path) -> None:
    path = tmp_path / "telemetry.jsonl"
    path.symlink_to("/dev/full")
    writer = TelemetryWriter(path)
    with pytest.raises(OSError, match=f"^cannot write the telemetry {path}: No space left on device$"):
        writer.write({"frame": 0, "t": 0.0})
    assert writer.records == 0
