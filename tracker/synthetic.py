"""Small rendered sequences with known boxes: a textured target on a textured background.

Optional: a static occluder the target passes fully behind, and a steady scale change.
Used by the tests, so they need no downloaded footage.
"""
from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from tracker.boxes import Box


@dataclass(frozen=True)
class SyntheticSequence:
    """Frames, the target's true box in each, and whether it is visible (not fully hidden)."""

    frames: list[np.ndarray]
    boxes: list[Box]
    visible: list[bool]


def texture(height: int, width: int, rng: np.random.Generator, cell: int, contrast: float) -> np.ndarray:
    """A colour texture of random blocks of about ``cell`` pixels, blurred slightly."""
    small = rng.uniform(128 - 127 * contrast, 128 + 127 * contrast,
                        (max(1, height // cell + 1), max(1, width // cell + 1), 3))
    big = cv2.resize(small.astype(np.float32), (width, height), interpolation=cv2.INTER_NEAREST)
    return cv2.GaussianBlur(big, (3, 3), 0).clip(0, 255).astype(np.uint8)


def render_sequence(frames: int = 60, frame_size: tuple[int, int] = (320, 240), target: int = 40,
                    speed: float = 3.0, scale_change: float = 1.0, occlusion: tuple[int, int] | None = None,
                    seed: int = 0) -> SyntheticSequence:
    """A target moving left to right with a gentle vertical wave.

    ``scale_change`` is the final/initial size ratio; ``occlusion = (start, end)`` places a
    static occluder over the target's path for those frames, wide enough to hide it fully.
    """
    width, height = frame_size
    rng = np.random.default_rng(seed)
    background = texture(height, width, rng, cell=16, contrast=0.35)
    look = texture(target, target, rng, cell=6, contrast=1.0)
    boxes = []
    for i in range(frames):
        size = target * (1.0 + (scale_change - 1.0) * i / max(1, frames - 1))
        cx = 0.2 * width + speed * i
        cy = height / 2 + 0.15 * height * np.sin(i / 12.0)
        boxes.append((cx - size / 2, cy - size / 2, size, size))
    occluder = _occluder(boxes, occlusion) if occlusion else None
    occluder_look = texture(height, width, rng, cell=10, contrast=0.6)
    images, visible = [], []
    for box in boxes:
        image = background.copy()
        _paste(image, look, box)
        if occluder is not None:
            ox, oy, ow, oh = occluder
            image[oy:oy + oh, ox:ox + ow] = occluder_look[oy:oy + oh, ox:ox + ow]
        images.append(image)
        visible.append(occluder is None or not _inside(box, occluder))
    return SyntheticSequence(images, boxes, visible)


def _occluder(boxes: list[Box], occlusion: tuple[int, int]) -> tuple[int, int, int, int]:
    """The smallest static box (plus a margin) that covers the target during ``occlusion``."""
    start, end = occlusion
    inside = boxes[start:end]
    x0 = min(b[0] for b in inside) - 4
    y0 = min(b[1] for b in inside) - 4
    x1 = max(b[0] + b[2] for b in inside) + 4
    y1 = max(b[1] + b[3] for b in inside) + 4
    return (int(np.floor(x0)), int(np.floor(y0)), int(np.ceil(x1 - x0)), int(np.ceil(y1 - y0)))


def _inside(box: Box, outer: tuple[int, int, int, int]) -> bool:
    x, y, w, h = box
    ox, oy, ow, oh = outer
    return x >= ox and y >= oy and x + w <= ox + ow and y + h <= oy + oh


def _paste(image: np.ndarray, look: np.ndarray, box: Box) -> None:
    x, y, w, h = (int(round(v)) for v in box)
    patch = cv2.resize(look, (w, h), interpolation=cv2.INTER_LINEAR)
    height, width = image.shape[:2]
    x0, y0, x1, y1 = max(x, 0), max(y, 0), min(x + w, width), min(y + h, height)
    if x1 > x0 and y1 > y0:
        image[y0:y1, x0:x1] = patch[y0 - y:y1 - y, x0 - x:x1 - x]
