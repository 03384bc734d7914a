"""Summary JSON (atomic rewrites) and latency percentiles."""
from __future__ import annotations

import errno
import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

import pipelines.outputs.summary
from pipelines.outputs.latency import latency_percentiles
from pipelines.outputs.summary import write_summary


def test_summary_is_rewritten_in_place(tmp_path: Path) -> None:
    path = tmp_path / "summary.json"
    write_summary(path, {"frames": 10, "complete": False})
    write_summary(path, {"frames": 20, "complete": True, "latency_ms": {"p50": np.float64(12.5)}})
    assert json.loads(path.read_text()) == {"frames": 20, "complete": True, "latency_ms": {"p50": 12.5}}
    assert os.listdir(tmp_path) == ["summary.json"]


def test_failed_write_keeps_the_previous_summary(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "summary.json"
    write_summary(path, {"frames": 10})

    def crash(src: str, dst: str) -> None:
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", crash)
    with pytest.raises(OSError, match="disk full"):
        write_summary(path, {"frames": 20})
    assert json.loads(path.read_text()) == {"frames": 10}
    assert os.listdir(tmp_path) == ["summary.json"]


def test_unserialisable_summary_leaves_the_file_alone(tmp_path: Path) -> None:
    path = tmp_path / "summary.json"
    write_summary(path, {"frames": 1})
    with pytest.raises(TypeError):
        write_summary(path, {"frames": object()})
    assert json.loads(path.read_text()) == {"frames": 1}


def test_sync_false_skips_only_the_fsync(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "summary.json"
    synced: list[int] = []
    monkeypatch.setattr(os, "fsync", synced.append)
    write_summary(path, {"frames": 10}, sync=False)
    assert synced == [] and json.loads(path.read_text()) == {"frames": 10}
    write_summary(path, {"frames": 20})
    assert len(synced) == 1 and json.loads(path.read_text()) == {"frames": 20}
    assert os.listdir(tmp_path) == ["summary.json"]


def test_latency_percentiles() -> None:
    stats = latency_percentiles(float(v) for v in range(1, 101))
    assert stats["count"] == 100 and stats["max"] == 100.0
    assert (stats["p50"], stats["p95"], stats["p99"]) == pytest.approx((50.5, 95.05, 99.01))


def test_latency_percentiles_ignore_non_finite_and_handle_empty() -> None:
    assert latency_percentiles([math.nan, 4.0, math.inf])["p99"] == 4.0
    assert latency_percentiles([]) == {"count": 0, "p50": None, "p95": None, "p99": None, "max": None}


def _disk_full(*args: object, **kwargs: object) -> None:
    raise OSError(errno.ENOSPC, "No space left on device")


def test_on_a_full_disk_the_summary_is_rewritten_in_its_own_space(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """No room for the temporary copy once left the summary stale ("running") after a run ended."""
    path = tmp_path / "summary.json"
    write_summary(path, {"status": "running", "frames": 1})
    monkeypatch.setattr(pipelines.outputs.summary, "atomic_write", _disk_full)
    write_summary(path, {"status": "output failed", "frames": 53})
    assert json.loads(path.read_text()) == {"status": "output failed", "frames": 53}
    with pytest.raises(OSError):  # no file yet: no space of its own to reuse
        write_summary(tmp_path / "new.json", {"status": "running"})
    with pytest.raises(OSError):  # more than the file's own space
        write_summary(path, {"status": "x" * 20_000})
    assert json.loads(path.read_text())["frames"] == 53


# A summary rewritten in its own space on a full disk may be shorter than the one it replaces: the
# file is cut to the new text, or the old one's tail would be left after it and the JSON unreadable.
def test_a_shorter_summary_on_a_full_disk_leaves_no_tail(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "summary.json"
    write_summary(path, {"status": "running", "frames": 1, "notes": "x" * 300})

    def disk_full(*args: object, **kwargs: object) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(pipelines.outputs.summary, "atomic_write", disk_full)
    write_summary(path, {"status": "output failed", "frames": 2})
    assert json.loads(path.read_text()) == {"status": "output failed", "frames": 2}
