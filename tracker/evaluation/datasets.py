"""Benchmark sequences: OTB and VOT folders, plain image folders and video files."""
from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from tracker.runtime.boxes import Box, polygon_to_box

IMAGE_SUFFIXES = {".jpg", ".jpeg", ".png", ".bmp", ".tif", ".tiff", ".webp"}
VIDEO_SUFFIXES = {".avi", ".mp4", ".mov", ".mkv", ".webm", ".m4v", ".mpg", ".mpeg"}
GROUNDTRUTH_NAMES = ("groundtruth_rect.txt", "groundtruth.txt")
FRAME_DIRS = ("img", "imgs", "color")
#: Frame rate assumed for timestamps when a sequence does not tell its own (OTB sequences are 30 fps).
ASSUMED_FPS = 30.0


class FrameReadError(ValueError):
    """A frame of a sequence cannot be read: a damaged image, or a video that ends early."""


@dataclass(frozen=True)
class Sequence:
    """Frames (image files or one video) and, when known, one ground-truth box per frame."""

    name: str
    frame_paths: tuple[Path, ...] = ()
    video_path: Path | None = None
    groundtruth: tuple[Box, ...] | None = None

    def __len__(self) -> int:
        if self.groundtruth is not None:
            return len(self.groundtruth)
        if self.video_path is not None:
            return _video_frame_count(self.video_path)
        return len(self.frame_paths)

    def frames(self) -> Iterator[np.ndarray]:
        """The BGR frames in order; ``FrameReadError`` names the sequence and the frame that fails."""
        if self.video_path is not None:
            yield from _read_video(self.name, self.video_path, len(self))
            return
        for number, path in enumerate(self.frame_paths[:len(self)], start=1):
            image = cv2.imread(str(path), cv2.IMREAD_COLOR)
            if image is None:
                raise FrameReadError(f"{self.name}: cannot read frame {number} ({path})")
            yield image


def parse_groundtruth(path: Path) -> tuple[Box, ...]:
    """Boxes from an OTB ``x,y,w,h`` or VOT 8-value polygon file (comma, tab or space separated).

    Line n is frame n's box (``NaN`` or zero values where the subject is not visible, as UAV123, OTB
    and VOT write them). A UTF-8 byte-order mark and blank lines at the end are ignored; a blank line
    before the last box is an error, since skipping it would pair every later box with the wrong frame.
    """
    try:
        lines = Path(path).read_text(encoding="utf-8-sig").splitlines()
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a text file of boxes") from None
    while lines and not lines[-1].strip():
        lines.pop()
    if not lines:
        raise ValueError(f"{path}: no ground-truth boxes")
    return tuple(_parse_box(path, number, line.strip()) for number, line in enumerate(lines, start=1))


def _parse_box(path: Path, number: int, text: str) -> Box:
    """Line ``number`` of ``path``: 4 values (x,y,w,h) or 8 (a polygon, turned into its min/max box)."""
    if not text:
        raise ValueError(f"{path}:{number}: blank line (each line is one frame's box; NaN,NaN,NaN,NaN "
                         "marks a frame without the subject)")
    try:
        values = [float(v) for v in re.split(r"[,\s]+", text)]
    except ValueError:
        raise ValueError(f"{path}:{number}: not numbers: {text!r}") from None
    if len(values) == 4:
        return values[0], values[1], values[2], values[3]
    if len(values) == 8:
        return polygon_to_box(values)
    raise ValueError(f"{path}:{number}: expected 4 (x,y,w,h) or 8 (polygon) values, got {len(values)}")


def load_sequence(path: str | Path, groundtruth: str | Path | None = None) -> Sequence:
    """A sequence from a folder (OTB ``img/``, VOT ``imgs/`` or images directly) or a video file.

    The ground truth is ``groundtruth`` when given, else a ``groundtruth_rect.txt`` /
    ``groundtruth.txt`` found in the folder (beside a video: those names, ``<stem>.txt`` or
    ``<stem>_groundtruth.txt``).
    """
    if isinstance(path, str) and not path.strip():  # Path("") would be the current folder
        raise FileNotFoundError("an empty sequence path (use . for the current folder)")
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"no such sequence: {path}")
    if path.is_file():
        if path.suffix.lower() not in VIDEO_SUFFIXES:
            raise ValueError(f"not a video file or sequence folder: {path}")
        gt_path = Path(groundtruth) if groundtruth else _find_groundtruth(path.parent, path.stem + ".txt",
                                                                            path.stem + "_groundtruth.txt")
        truth = parse_groundtruth(gt_path) if gt_path else None
        if truth is not None:
            _check_box_count(gt_path, len(truth), path, _video_frame_count(path))
        return Sequence(path.stem, video_path=path, groundtruth=truth)
    frames = _find_frames(path)
    gt_path = Path(groundtruth) if groundtruth else _find_groundtruth(path)
    truth = parse_groundtruth(gt_path) if gt_path else None
    if truth is not None:
        _check_box_count(gt_path, len(truth), path, len(frames))
    return Sequence(path.name, frame_paths=frames, groundtruth=truth)


def _check_box_count(gt_path: Path, boxes: int, path: Path, frames: int) -> None:
    """One box per frame, from the first: any other count would pair boxes with the wrong frames
    (a video's count is its header's)."""
    if boxes > frames:
        raise ValueError(f"{gt_path} has {boxes} boxes but {path} has only {frames} frames")
    if boxes < frames:
        raise ValueError(f"{gt_path} has {boxes} boxes but {path} has {frames} frames: one box per frame is needed "
                         "(an annotation that starts at a later frame, as some OTB-2015 sequences' do, needs the "
                         "frames before it removed)")


def _natural_key(path: Path) -> list[int | str]:
    return [int(part) if part.isdigit() else part.lower() for part in re.split(r"(\d+)", path.name)]


def list_images(folder: Path) -> list[Path]:
    """The image files directly in ``folder`` in natural name order (``2.jpg`` before ``10.jpg``)."""
    return sorted((p for p in Path(folder).iterdir() if p.suffix.lower() in IMAGE_SUFFIXES and p.is_file()),
                  key=_natural_key)


def frame_folder(folder: Path) -> Path:
    """Where a sequence folder keeps its frames: its ``img/``, ``imgs/`` or ``color/`` (OTB, VOT)
    when one holds images, else the folder itself."""
    for candidate in (folder / d for d in FRAME_DIRS):
        if candidate.is_dir() and list_images(candidate):
            return candidate
    return folder


def _find_frames(folder: Path) -> tuple[Path, ...]:
    images = list_images(frame_folder(folder))
    if not images:
        raise ValueError(f"no image frames in {folder} (looked in {', '.join(FRAME_DIRS)} and the folder itself)")
    return tuple(images)


def _find_groundtruth(folder: Path, *extra_names: str) -> Path | None:
    for name in (*GROUNDTRUTH_NAMES, *extra_names):
        if (folder / name).is_file():
            return folder / name
    return None


def _open_video(path: Path) -> cv2.VideoCapture:
    capture = cv2.VideoCapture(str(path))
    if not capture.isOpened():
        raise ValueError(f"cannot open video {path}")
    return capture


def _video_frame_count(path: Path) -> int:
    capture = _open_video(path)
    try:
        return int(capture.get(cv2.CAP_PROP_FRAME_COUNT))
    finally:
        capture.release()


def _read_video(name: str, path: Path, count: int) -> Iterator[np.ndarray]:
    """The first ``count`` frames of ``path``; ``FrameReadError`` when it ends (or breaks) before."""
    capture = _open_video(path)
    try:
        for number in range(1, count + 1):
            ok, frame = capture.read()
            if not ok:
                raise FrameReadError(f"{name}: cannot read frame {number} of the {count} in {path} "
                                     "(truncated or damaged?)")
            yield frame
    finally:
        capture.release()
