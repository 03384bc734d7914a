"""Fixtures for the pipelines tests: small generated videos and image folders."""
from __future__ import annotations

import subprocess
import sys
import textwrap
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest

from tests.support import write_clip


def _frame_image(index: int, size: tuple[int, int] = (96, 64)) -> np.ndarray:
    """A frame whose mean brightness encodes ``index`` (step 10) with a moving square for texture."""
    width, height = size
    image = np.full((height, width, 3), (20 + 10 * index) % 256, np.uint8)
    x = (5 * index) % (width - 16)
    cv2.rectangle(image, (x, 20), (x + 15, 35), (255, 255, 255), cv2.FILLED)
    return image


def _write_video(path: Path, frames: int, fps: float = 25.0, size: tuple[int, int] = (96, 64)) -> Path:
    return write_clip(path, (_frame_image(index, size) for index in range(frames)), fps, "mp4v")


@pytest.fixture
def small_video(tmp_path: Path) -> Path:
    """12 frames of 96x64 at 25 fps, mp4v in .mp4."""
    return _write_video(tmp_path / "clip.mp4", 12)


@pytest.fixture
def frame_image() -> Callable[..., np.ndarray]:
    """``frame_image(index, size=(96, 64))``: brightness ``(20 + 10 * index) % 256``, a moving white square."""
    return _frame_image


@pytest.fixture
def write_video() -> Callable[..., Path]:
    """``write_video(path, frames, fps=25.0, size=(96, 64))`` of ``frame_image`` frames, mp4v."""
    return _write_video


def _run_and_crash(code: str) -> None:
    """Run ``code`` in a fresh interpreter that then dies with ``os._exit`` (no close, no atexit)."""
    script = textwrap.dedent(code) + "\nimport os\nos._exit(3)\n"
    result = subprocess.run([sys.executable, "-c", script], cwd=Path(__file__).parents[2],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 3, result.stderr


@pytest.fixture
def run_and_crash() -> Callable[[str], None]:
    """``run_and_crash(code)``: run code in a child interpreter that dies without closing anything."""
    return _run_and_crash
