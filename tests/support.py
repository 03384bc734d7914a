"""What tests in several folders share: polling, running the CLI in a subprocess, a free UDP port,
writing a video clip and a sequence folder."""
from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Callable, Iterable
from typing import Any
from pathlib import Path

import cv2
import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


def wait_until(predicate: Callable[[], object], timeout: float, step: float = 0.01) -> bool:
    """Poll ``predicate`` every ``step`` s until it is true or ``timeout`` s have passed; whether it
    became true (it is asked once more at the deadline)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(step)
    return bool(predicate())


def signalled(command: list[str], ready: Callable[[subprocess.Popen[str]], object],
              signum: int = signal.SIGTERM, timeout: float = 30.0, **popen: Any) -> tuple[int, str, str]:
    """Run ``command``, send it ``signum`` once ``ready(process)`` says it is under way, and return
    (exit status, stdout, stderr); a process still alive after ``timeout`` s is killed."""
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **popen)
    try:
        assert ready(process), "the run never got under way"
        process.send_signal(signum)
        stdout, stderr = process.communicate(timeout=timeout)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    return process.returncode, stdout, stderr


def cli_command(*args: str) -> list[str]:
    """``gimbaltrack ARGS`` as a subprocess command line, whatever is installed."""
    return [sys.executable, "-c", "import sys; from pipelines.cli import main; sys.exit(main())", *args]


def subprocess_env(can_port: int | None = None) -> dict[str, str]:
    """The environment for CLI subprocesses; ``can_port`` isolates udp_multicast traffic from
    every other test on the machine (python-can reads ``CAN_CONFIG``)."""
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PYTHONUNBUFFERED": "1"}
    if can_port is not None:
        env["CAN_CONFIG"] = json.dumps({"port": can_port})
    return env


def require_ffmpeg(purpose: str) -> str:
    """The ffmpeg program's path; fails in CI (scripts/test.sh installs it), else skips the test."""
    found = shutil.which("ffmpeg")
    if found is None:
        message = f"ffmpeg is not installed (scripts/test.sh installs it): cannot test {purpose}"
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip(message)
    return found


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def write_clip(path: Path, images: Iterable[np.ndarray], fps: float, fourcc: str) -> Path:
    """Encode ``images`` (BGR, all one size) with FFmpeg as ``fourcc`` at ``fps``."""
    writer = None
    for image in images:
        if writer is None:
            height, width = image.shape[:2]
            writer = cv2.VideoWriter(str(path), cv2.CAP_FFMPEG, cv2.VideoWriter_fourcc(*fourcc), fps,
                                     (width, height))
            assert writer.isOpened()
        writer.write(image)
    assert writer is not None, "no images to write"
    writer.release()
    return path


def write_sequence_folder(folder: Path, frames: Iterable[np.ndarray], boxes: Iterable[Iterable[float]]) -> Path:
    """An OTB-style sequence in ``folder``: ``1.png``, ``2.png``, ... and comma-separated ground truth."""
    for i, image in enumerate(frames, start=1):
        cv2.imwrite(str(folder / f"{i}.png"), image)
    (folder / "groundtruth_rect.txt").write_text("".join(",".join(f"{v:.2f}" for v in b) + "\n" for b in boxes))
    return folder
