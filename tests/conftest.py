"""Fixtures shared by the whole suite."""
from __future__ import annotations

import os
from pathlib import Path

import pytest

from tracker.data_paths import DATA_ENV, shared_data_dir


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The shared benchmark data: fails under CI when missing, skips (with the reason) elsewhere."""
    root = shared_data_dir()
    if (root / "sequences").is_dir():
        return root
    message = f"shared data not found at {root} (set {DATA_ENV} to its location)"
    if os.environ.get("CI"):
        pytest.fail(message)
    pytest.skip(message)
