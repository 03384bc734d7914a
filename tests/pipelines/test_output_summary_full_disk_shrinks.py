"""A summary rewritten in its own space on a full disk may be shorter than the one it replaces: the
file is cut to the new text, or the old one's tail would be left after it and the JSON unreadable."""
from __future__ import annotations

import errno
import json
from pathlib import Path

import pytest

import pipelines.outputs.summary
from pipelines.outputs.summary import write_summary


def test_a_shorter_summary_on_a_full_disk_leaves_no_tail(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "summary.json"
    write_summary(path, {"status": "running", "frames": 1, "notes": "x" * 300})

    def disk_full(*args: object, **kwargs: object) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(pipelines.outputs.summary, "atomic_write", disk_full)
    write_summary(path, {"status": "output failed", "frames": 2})
    assert json.loads(path.read_text()) == {"status": "output failed", "frames": 2}
