"""BackgroundVideoWriter: a failure in its worker reaches the next ``write`` (so a run ends when its
video cannot be written, not only at the end), once."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pipelines.outputs.annotated_video import BackgroundVideoWriter
from tests.support import wait_until


def test_a_worker_failure_is_raised_by_a_later_write(tmp_path: Path) -> None:
    writer = BackgroundVideoWriter(tmp_path / "bad.avi", (64, 48), 10.0)
    writer.write(np.zeros((10, 10, 3), np.uint8))  # wrong size: fails in the worker thread
    good = np.zeros((48, 64, 3), np.uint8)

    def write_fails() -> bool:
        try:
            writer.write(good)
        except ValueError as exc:
            assert "frame is 10x10" in str(exc)
            return True
        return False

    assert wait_until(write_fails, timeout=10.0)
    writer.write(good)  # already reported: quiet, and the worker keeps draining
    writer.close()
