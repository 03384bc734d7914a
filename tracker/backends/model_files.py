"""Finding optional model files in a user-given model directory."""
from __future__ import annotations

from pathlib import Path


def find_model_file(model_dir: str | Path | None, subdir: str, pattern: str, what: str) -> Path:
    """The first file matching ``pattern`` in ``model_dir`` or ``model_dir/subdir``.

    Raises ``FileNotFoundError`` naming the missing file and where it was looked for.
    """
    if model_dir is None:
        raise FileNotFoundError(f"{what} needs model files: pass a model directory holding {pattern}")
    root = Path(model_dir)
    for folder in (root, root / subdir):
        matches = sorted(folder.glob(pattern)) if folder.is_dir() else []
        if matches:
            return matches[0]
    raise FileNotFoundError(f"{what}: no {pattern} in {root} or {root / subdir}")


def checked_model_dir(model_dir: str | Path | None) -> Path | None:
    """``model_dir`` as a ``Path`` (``None`` as it is); ``FileNotFoundError`` when it is no folder,
    so a mistyped path is not quietly taken for a folder without models."""
    if model_dir is None:
        return None
    path = Path(model_dir)
    if not path.is_dir():
        raise FileNotFoundError(f"model directory {str(model_dir)!r} is not a folder")
    return path
