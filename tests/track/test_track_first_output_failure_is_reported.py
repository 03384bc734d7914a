"""On a full disk several outputs fail one after the other: the summary keeps the failure that
ended the run, not the last one met while finalising the others."""
from __future__ import annotations

import errno
import json
from pathlib import Path

import pytest

import pipelines.track_session
from tests.track.helpers import DEMO, DEMO_ROI, run_track


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_the_failure_that_ended_the_run_stays_in_the_summary(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    def disk_full(*args: object, **kwargs: object) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(pipelines.track_session, "write_timeseries_png", disk_full)
    out = tmp_path / "out"
    out.mkdir()
    (out / "can.log").symlink_to("/dev/full")  # full from the first frame on; the plot fails at the end
    assert run_track(DEMO, out, "--roi", DEMO_ROI, "--no-video") == 1
    assert "cannot write the CAN log" in capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "output failed" and "cannot write the CAN log" in summary["error"]
    assert "plot" not in summary["outputs"]
