"""``gimbaltrack track --console`` in a subprocess against the built-in simulated gimbal: its
console's URL, its outputs, and what the operator's actions put on the bus."""
from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path
from typing import Any

from tests.support import subprocess_env
from tests.track.helpers import BOX, Position, make_clip, start, track_command

FRAMES = 900  # 30 s at --realtime: the tests stop the run from the console long before


def drifting_slowly(i: int) -> tuple[int, int]:
    """Left of centre, moving right a pixel every other frame."""
    return 60 + i // 2, 100


def subject_box(frame: int, position: Position = drifting_slowly) -> list[int]:
    x, y = position(frame)
    return [x, y, BOX, BOX]


def standing(i: int) -> tuple[int, int]:
    """A subject that stays where it is, left of centre."""
    return 60, 100


def crossing(i: int) -> tuple[int, int]:
    """Another thing, crossing the picture right to left and round again (what a motion detector
    finds first, and the operator corrects)."""
    return 300 - (3 * i) % 300, 160


class ConsoleRun:
    """The run and its console: ``port``, ``url``; ``finish()`` waits for it to end."""

    def __init__(self, tmp_path: Path, *extra: str, console: str = "127.0.0.1:0",
                 position: Position = drifting_slowly, other: Position | None = None,
                 source: str | None = None, env: dict[str, str] | None = None) -> None:
        """A clip of ``position`` (and ``other``) played at its own rate, or ``source`` as given."""
        if source is None:
            source = str(make_clip(tmp_path / "clip.avi", FRAMES, position, other=other))
            extra = ("--realtime", *extra)
        self.out = tmp_path / "out"
        self.process = start(track_command(source, self.out, "--detect", "motion", "--console", console, *extra),
                             env or subprocess_env())
        self.stderr_lines: list[str] = []
        for line in self.process.stderr:
            self.stderr_lines.append(line)
            found = re.search(r"console at (http://\S+)", line)
            if found:
                self.url = found.group(1)
                self.port = int(re.search(r":(\d+)/", self.url).group(1))
                return
        self.process.wait()
        raise AssertionError(f"no console URL; exit {self.process.returncode}: {''.join(self.stderr_lines)}")

    def finish(self, timeout: float = 60.0) -> tuple[int, str, str]:
        try:
            stdout, stderr = self.process.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.process.kill()
            stdout, stderr = self.process.communicate()
        return self.process.returncode, stdout, "".join(self.stderr_lines) + stderr

    def kill(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.communicate()

    def summary(self) -> dict[str, Any]:
        return json.loads((self.out / "summary.json").read_text())
