"""Small rendered sequences with known boxes: a textured target on a textured background.

Optional: a static occluder the target passes fully behind, a steady scale change, and a camera
that pans or shakes over a larger world. Used by the tests, so they need no downloaded footage.
"""
from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from tracker.runtime.boxes import Box


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
                    seed: int = 0, pan: float = 0.0, shake: float = 0.0) -> SyntheticSequence:
    """A target moving left to right (in the world) with a gentle vertical wave.

    ``scale_change`` is the final/initial size ratio; ``occlusion = (start, end)`` places a
    static occluder over the target's path for those frames, wide enough to hide it fully.
    ``pan`` turns the camera right by that many px a frame and ``shake`` moves it by up to that
    many px in x and y at random each frame (hand-held); boxes are in the image.
    """
    width, height = frame_size
    rng = np.random.default_rng(seed)
    views = _camera_path(frames, pan, shake, seed)
    world_w = width + int(np.ceil(max(x for x, _ in views)))
    world_h = height + int(np.ceil(max(y for _, y in views)))
    background = texture(world_h, world_w, rng, cell=16, contrast=0.35)
    look = texture(target, target, rng, cell=6, contrast=1.0)
    world_boxes = []
    for i in range(frames):
        size = target * (1.0 + (scale_change - 1.0) * i / max(1, frames - 1))
        cx = views[0][0] + 0.2 * width + speed * i
        cy = views[0][1] + height / 2 + 0.15 * height * np.sin(i / 12.0)
        world_boxes.append((cx - size / 2, cy - size / 2, size, size))
    occluder = _occluder(world_boxes, occlusion) if occlusion else None
    occluder_look = texture(world_h, world_w, rng, cell=10, contrast=0.6)
    images, boxes, visible = [], [], []
    for box, (vx, vy) in zip(world_boxes, views):
        world = background.copy()
        _paste(world, look, box)
        if occluder is not None:
            ox, oy, ow, oh = occluder
            world[oy:oy + oh, ox:ox + ow] = occluder_look[oy:oy + oh, ox:ox + ow]
        images.append(_view(world, vx, vy, frame_size))
        boxes.append((box[0] - vx, box[1] - vy, box[2], box[3]))
        visible.append(occluder is None or not _inside(box, occluder))
    return SyntheticSequence(images, boxes, visible)


def _camera_path(frames: int, pan: float, shake: float, seed: int) -> list[tuple[float, float]]:
    """Where each frame's view starts in the world (x, y >= 0): ``pan`` px a frame plus up to
    ``shake`` px of random jitter each way; all (0, 0) for a still camera."""
    jitter = np.random.default_rng(seed + 1).uniform(-shake, shake, (frames, 2))
    xs = pan * np.arange(frames) + jitter[:, 0]
    ys = jitter[:, 1]
    return [(float(x), float(y)) for x, y in zip(xs - xs.min(), ys - ys.min())]


def _view(world: np.ndarray, x: float, y: float, frame_size: tuple[int, int]) -> np.ndarray:
    """The part of ``world`` of ``frame_size`` whose top-left corner is at (x, y), sub-pixel."""
    width, height = frame_size
    if x.is_integer() and y.is_integer():
        return world[int(y):int(y) + height, int(x):int(x) + width].copy()
    shift = np.float32([[1, 0, -x], [0, 1, -y]])
    return cv2.warpAffine(world, shift, (width, height), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)


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
