"""Where the shared benchmark data lives: ``$GIMBALTRACK_DATA`` or ``../shared/data``."""
from __future__ import annotations

import os
from pathlib import Path

PROJECT_ROOT = Path(__file__).resolve().parents[2]
DATA_ENV = "GIMBALTRACK_DATA"


def shared_data_dir() -> Path:
    """The shared data folder (it may not exist on a user's machine)."""
    override = os.environ.get(DATA_ENV)
    return Path(override) if override else PROJECT_ROOT.parent / "shared" / "data"


def shared_sequences() -> list[Path]:
    """Every sequence folder under ``sequences/``, sorted; empty when the data is absent."""
    root = shared_data_dir() / "sequences"
    return sorted(p for p in root.iterdir() if p.is_dir()) if root.is_dir() else []
