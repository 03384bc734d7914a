"""A telemetry line that cannot be written (a full disk) raises an ``OSError`` naming the file, so
the one-line error of the run says which output failed."""
from __future__ import annotations

from pathlib import Path

import pytest

from pipelines.outputs.telemetry import TelemetryWriter


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_a_failed_write_names_the_telemetry_file(tmp_path: Path) -> None:
    path = tmp_path / "telemetry.jsonl"
    path.symlink_to("/dev/full")
    writer = TelemetryWriter(path)
    with pytest.raises(OSError, match=f"^cannot write the telemetry {path}: No space left on device$"):
        writer.write({"frame": 0, "t": 0.0})
    assert writer.records == 0
