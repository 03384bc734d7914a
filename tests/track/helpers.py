"""What the track tests share: synthetic clips, running the CLI, reading the recorded command stream."""
from __future__ import annotations

import signal
import subprocess
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import can
import cv2
import numpy as np

from gimbal.client import SPEED_RELEASE
from gimbal.log_decode import HOST_TO_GIMBAL, decode_frames
from gimbal.transport import HOST_TX_ID
from gimbal.messages.motion import SPEED_RANGE, SPEED_TAKE_CONTROL
from pipelines.cli import main
from tests.support import ROOT, cli_command, write_clip

DEMO = ROOT / "samples" / "demo.mp4"
DEMO_ROI = (ROOT / "samples" / "demo_roi.txt").read_text().strip()
SIZE = (320, 240)
BOX = 40  # the synthetic subject's side in pixels

Position = Callable[[int], tuple[int, int] | None]  # frame index -> subject top-left, None: gone


def make_clip(path: Path, frames: int, position: Position, fps: float = 30.0,
              other: Position | None = None, size: tuple[int, int] = SIZE) -> Path:
    """A Motion JPEG clip of ``size`` (w, h): a fixed textured background and a checkered square at
    ``position(i)``; with ``other``, a striped square of the same size (another thing, which does
    not look like it) at ``other(i)``, behind the subject."""
    rng = np.random.default_rng(7)
    width, height = size
    background = cv2.GaussianBlur(rng.integers(60, 200, (height, width, 3), dtype=np.uint8), (5, 5), 0)
    tile = np.indices((BOX, BOX)).sum(axis=0) // 8 % 2
    subject = np.where(tile[..., None] == 1, (20, 40, 230), (240, 240, 30)).astype(np.uint8)
    stripes = np.where(np.indices((BOX, BOX))[1][..., None] // 5 % 2 == 1, (235, 235, 235), (20, 20, 20))
    looks = [(stripes.astype(np.uint8), other or (lambda i: None)), (subject, position)]

    def image(i: int) -> np.ndarray:
        image = background.copy()
        for look, place in looks:
            where = place(i)
            if where is not None:  # the square may stand partly outside the frame
                x, y = where
                x0, y0 = max(x, 0), max(y, 0)
                visible = look[y0 - y:max(0, min(BOX, height - y)), x0 - x:max(0, min(BOX, width - x))]
                image[y0:y0 + visible.shape[0], x0:x0 + visible.shape[1]] = visible
        return image

    return write_clip(path, (image(i) for i in range(frames)), fps, "MJPG")


def drifting(i: int) -> tuple[int, int]:
    """A subject drifting right by a pixel a frame, left of and above the centre."""
    return 140 + i, 100


def out_right_and_back(back_at: int, y: int) -> Position:
    """A subject walking right at 6 px a frame from x = 140 until it is out of view (frame 30 on),
    then from frame ``back_at`` coming back in from the right at the same speed, at height ``y``."""
    def position(i: int) -> tuple[int, int] | None:
        if i < back_at:
            x = 140 + 6 * i
            return (x, y) if x < SIZE[0] else None
        return SIZE[0] - 6 * (i - back_at), y
    return position


def roi_at(position: Position) -> str:
    x, y = position(0)  # type: ignore[misc]
    return f"{x},{y},{BOX},{BOX}"


def run_track(source: Path | str, out: Path, *extra: str) -> int:
    """``gimbaltrack track`` in this process against the built-in simulator."""
    return main(["track", str(source), "--out", str(out), "--quiet", *extra])


def track_command(source: Path | str, out: Path, *extra: str) -> list[str]:
    return cli_command("track", str(source), "--out", str(out), "--quiet", *extra)


@dataclass(frozen=True)
class SpeedCommand:
    t: float
    yaw: float  # deg/s
    pitch: float
    roll: float
    ctrl: int

    @property
    def zero(self) -> bool:
        return self.yaw == self.pitch == self.roll == 0.0

    @property
    def released(self) -> bool:
        return not self.ctrl & SPEED_TAKE_CONTROL


def decoded(can_log: Path) -> list[dict[str, Any]]:
    """Every packet in the log as recorded; the client leaves out the bus's echo of its own frames
    (udp_multicast loops every sent frame back to the sender), so no host frame is marked ``R``."""
    frames = list(can.LogReader(str(can_log)))
    assert not any(f.arbitration_id == HOST_TX_ID and f.is_rx for f in frames), "echo of a host frame logged"
    return list(decode_frames(frames))


def host_commands(records: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    return [r for r in records if r["direction"] == HOST_TO_GIMBAL and "error" not in r]


def speed_commands(records: Sequence[dict[str, Any]]) -> list[SpeedCommand]:
    """Every speed command the host sent, in order, with values in °/s."""
    out = []
    for r in host_commands(records):
        if r["name"] == "speed_control":
            f = r["fields"]
            out.append(SpeedCommand(r["timestamp"], f["yaw_speed"] / 10, f["pitch_speed"] / 10,
                                    f["roll_speed"] / 10, f["ctrl_byte"]))
    return out


def assert_stopped_at_end(records: Sequence[dict[str, Any]]) -> None:
    """The last speed command is zero with control released, after a zero still in control, and
    nothing after it moves the gimbal (only camera commands may follow)."""
    speeds = speed_commands(records)
    assert speeds, "no speed command in the log"
    assert speeds[-1].zero and speeds[-1].released and speeds[-1].ctrl == SPEED_RELEASE
    assert speeds[-2].zero
    motion = [r for r in host_commands(records) if r["cmd_set"] == 0x0E and r["name"] != "push_control"]
    assert motion[-1]["name"] == "speed_control" and motion[-1]["fields"]["ctrl_byte"] == SPEED_RELEASE


def in_speed_range(command: SpeedCommand) -> bool:
    low, high = SPEED_RANGE
    return all(low <= v * 10 <= high for v in (command.yaw, command.pitch, command.roll))


def _default_sigint() -> None:
    """A shell starts background jobs with SIGINT ignored, and Python keeps that; the signal tests
    need it delivered whoever started pytest."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def start(cmd: list[str], env: dict[str, str]) -> subprocess.Popen[str]:
    return subprocess.Popen(cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=_default_sigint)
