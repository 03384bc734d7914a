"""A mistyped ``model_dir`` is a FileNotFoundError naming it, as ``--model-dir`` is on the command
line, rather than quietly meaning "no models" (the correlation filter, the Haar face detector)."""
from __future__ import annotations

from pathlib import Path

import pytest

from tracker.detectors import make_detector
from tracker.runtime.registry import DEFAULT_BACKEND, make_tracker


@pytest.fixture(params=["missing", "file"])
def not_a_folder(request: pytest.FixtureRequest, tmp_path: Path) -> Path:
    path = tmp_path / "models"
    if request.param == "file":
        path.write_text("")
    return path


def test_make_tracker_refuses_it(not_a_folder: Path) -> None:
    with pytest.raises(FileNotFoundError, match="model directory .*models' is not a folder"):
        make_tracker("default", model_dir=not_a_folder)


@pytest.mark.parametrize("kind", ["face", "person", "motion"])
def test_make_detector_refuses_it(kind: str, not_a_folder: Path) -> None:
    with pytest.raises(FileNotFoundError, match="is not a folder"):
        make_detector(kind, model_dir=str(not_a_folder))


def test_a_folder_without_models_still_gives_the_defaults(tmp_path: Path) -> None:
    # issue #23: the default's model ships with the package, so an empty folder leaves it on those files
    assert make_tracker("default", model_dir=tmp_path).name == DEFAULT_BACKEND
    assert type(make_detector("face", model_dir=tmp_path)).__name__ == "HaarFaceDetector"
