"""Make the demo clips: a face-like figure moving over a drifting textured scene, passing behind a
post (demo.mp4, 640x360), and the same figure crossing a still, wide scene (demo_wide.mp4, 1280x720,
the closed-loop demo's: a virtual camera on the simulated gimbal looks into it).

Everything is drawn here from fixed seeds, so the clips and their ground truth are reproducible:

    .venv/bin/python samples/make_demo_clip.py        # writes demo.mp4, demo_groundtruth.txt, demo_roi.txt,
                                                      # demo_wide.mp4, demo_wide_groundtruth.txt

The ground truth is OTB style (``x,y,w,h`` per frame, top-left origin, pixels) and always gives the
subject's full box, also while the post hides it.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import cv2
import numpy as np

WIDTH, HEIGHT, FPS, SECONDS = 640, 360, 30, 9.0
SEED = 20240607
SPRITE_W, SPRITE_H = 64, 96  # subject box at scale 1
SUPERSAMPLE = 4
DRIFT = 12  # background margin in pixels on each side
POST_X, POST_W = 395, 100  # occluding post, in background coordinates (minus the margin)
# (time s, centre x, centre y, scale): the spline through them gives smooth motion whose speed varies.
KEYFRAMES = [
    (0.0, 170, 200, 1.00), (1.5, 250, 150, 1.00), (2.5, 320, 230, 1.00), (3.2, 250, 250, 1.05),
    (4.2, 190, 170, 1.10), (5.0, 320, 165, 1.15), (6.0, 520, 200, 1.25), (7.5, 575, 205, 1.40),
    (9.0, 560, 185, 1.50),
]
WIDE_WIDTH, WIDE_HEIGHT, WIDE_SECONDS, WIDE_SEED = 1280, 720, 6.0, 20261127
# The wide clip's path: from near the left edge (outside the central view a gimbal at rest sees)
# across the scene and back, at up to about 220 px/s (15 deg/s at the default 73.7 deg lens).
WIDE_KEYFRAMES = [
    (0.0, 120, 470, 1.5), (1.2, 330, 430, 1.5), (2.4, 560, 500, 1.5), (3.6, 820, 420, 1.5),
    (4.8, 1080, 460, 1.5), (6.0, 960, 500, 1.5),
]


def catmull_rom(times: np.ndarray, keyframes: list[tuple[float, ...]] = KEYFRAMES) -> np.ndarray:
    """Centre x, centre y and scale at ``times`` on a Catmull-Rom spline through ``keyframes``."""
    keys = np.array(keyframes, dtype=float)
    padded = np.vstack([keys[0], keys, keys[-1]])
    out = np.empty((len(times), 3))
    for n, t in enumerate(times):
        i = int(np.clip(np.searchsorted(keys[:, 0], t, side="right") - 1, 0, len(keys) - 2))
        p0, p1, p2, p3 = padded[i:i + 4, 1:]
        u = (t - keys[i, 0]) / (keys[i + 1, 0] - keys[i, 0])
        out[n] = 0.5 * (2 * p1 + (p2 - p0) * u + (2 * p0 - 5 * p1 + 4 * p2 - p3) * u ** 2
                        + (3 * p1 - p0 - 3 * p2 + p3) * u ** 3)
    return out


def make_background(rng: np.random.Generator, scale: int = 1) -> np.ndarray:
    """A scene larger than the frame: soft colour noise, a skyline of windowed blocks, paving stripes;
    ``scale`` times the 640x360 clip's scene in each direction (more blocks, same sizes)."""
    h, w = (HEIGHT + 2 * DRIFT) * scale, (WIDTH + 2 * DRIFT) * scale
    ground = 260 * scale
    noise = rng.uniform(0, 1, (9, 16, 3)).astype(np.float32)
    scene = cv2.resize(noise, (w, h), interpolation=cv2.INTER_CUBIC)
    scene = (np.clip(scene, 0, 1) * 70 + np.array([110, 120, 95], np.float32)).astype(np.uint8)
    for _ in range(14 * scale * scale):
        bx, bw = int(rng.integers(0, w - 40)), int(rng.integers(40, 110))
        top = int(rng.integers(30, ground - 90))
        shade = tuple(int(c) for c in rng.integers(60, 170, 3))
        cv2.rectangle(scene, (bx, top), (bx + bw, ground), shade, cv2.FILLED)
        for wy in range(top + 8, ground - 10, 18):
            for wx in range(bx + 6, bx + bw - 10, 16):
                lit = tuple(int(c) for c in rng.integers(150, 255, 3)) if rng.random() < 0.5 else (40, 40, 50)
                cv2.rectangle(scene, (wx, wy), (wx + 8, wy + 10), lit, cv2.FILLED)
    cv2.rectangle(scene, (0, ground), (w, h), (90, 100, 105), cv2.FILLED)
    for k in range(-10, 30 * scale):
        cv2.line(scene, (k * 40, h), (k * 40 + 120 * scale, ground), (120, 130, 135), 2, cv2.LINE_AA)
    return cv2.GaussianBlur(scene, (3, 3), 0)


def make_post(rng: np.random.Generator) -> np.ndarray:
    """The occluding post: a wooden-looking column as tall as the frame."""
    post = np.zeros((HEIGHT + 2 * DRIFT, POST_W, 3), np.uint8)
    post[:] = (40, 75, 120)
    for y in range(0, post.shape[0], 7):
        shade = int(rng.integers(-25, 25))
        cv2.line(post, (0, y), (POST_W, y + 3), (40 + shade, 75 + shade, 120 + shade), 2)
    cv2.rectangle(post, (0, 0), (POST_W - 1, post.shape[0] - 1), (25, 45, 70), 3)
    return post


def make_sprite() -> tuple[np.ndarray, np.ndarray]:
    """The subject at ``SUPERSAMPLE`` × its box size: a face with hair, eyes and mouth over a checked shirt."""
    s = SUPERSAMPLE
    w, h = SPRITE_W * s, SPRITE_H * s
    image = np.zeros((h, w, 3), np.uint8)
    mask = np.zeros((h, w), np.uint8)
    shoulders = np.array([[4, 96], [6, 64], [18, 54], [46, 54], [58, 64], [60, 96]]) * s
    cv2.fillPoly(mask, [shoulders], 255)
    checks = ((np.indices((h, w)) // (6 * s)).sum(axis=0) % 2).astype(bool)
    image[checks] = (40, 40, 200)
    image[~checks] = (230, 230, 240)
    cv2.ellipse(mask, (32 * s, 28 * s), (22 * s, 27 * s), 0, 0, 360, 255, cv2.FILLED)
    cv2.ellipse(image, (32 * s, 28 * s), (22 * s, 27 * s), 0, 0, 360, (120, 170, 225), cv2.FILLED)
    cv2.ellipse(image, (32 * s, 16 * s), (23 * s, 15 * s), 0, 180, 360, (30, 45, 70), cv2.FILLED)
    cv2.ellipse(mask, (32 * s, 16 * s), (23 * s, 15 * s), 0, 180, 360, 255, cv2.FILLED)
    for ex in (23, 41):
        cv2.ellipse(image, (ex * s, 27 * s), (5 * s, 3 * s), 0, 0, 360, (255, 255, 255), cv2.FILLED)
        cv2.circle(image, (ex * s, 27 * s), 2 * s, (60, 30, 10), cv2.FILLED)
    cv2.line(image, (32 * s, 30 * s), (30 * s, 38 * s), (90, 130, 190), s)
    cv2.ellipse(image, (32 * s, 43 * s), (8 * s, 4 * s), 0, 0, 180, (40, 40, 160), s + 1)
    return image, mask


def paste_sprite(frame: np.ndarray, sprite: np.ndarray, mask: np.ndarray,
                 cx: float, cy: float, scale: float) -> tuple[float, float, float, float]:
    """Alpha-blend the sprite centred at (cx, cy) with ``scale``; returns its box (x, y, w, h)."""
    k = scale / SUPERSAMPLE
    w, h = SPRITE_W * scale, SPRITE_H * scale
    x, y = cx - w / 2, cy - h / 2
    warp = np.array([[k, 0, x - 0.5 + k / 2], [0, k, y - 0.5 + k / 2]], np.float32)
    size = (frame.shape[1], frame.shape[0])
    layer = cv2.warpAffine(sprite, warp, size, flags=cv2.INTER_AREA)
    alpha = cv2.warpAffine(mask, warp, size, flags=cv2.INTER_AREA).astype(np.float32)[..., None] / 255
    frame[:] = (frame * (1 - alpha) + layer * alpha).astype(np.uint8)
    return x, y, w, h


def render(out_dir: Path) -> list[tuple[float, float, float, float]]:
    """Write demo.mp4, demo_groundtruth.txt and demo_roi.txt into ``out_dir``; return the boxes."""
    rng = np.random.default_rng(SEED)
    background, post = make_background(rng), make_post(rng)
    sprite, mask = make_sprite()
    n = int(SECONDS * FPS)
    times = np.arange(n) / FPS
    path = catmull_rom(times)
    # Whole-pixel camera shake: moves the scene without blurring it, which keeps the clip small.
    drift = np.round(np.stack([DRIFT * 0.8 * np.sin(2 * np.pi * times / 7.0),
                               DRIFT * 0.5 * np.sin(2 * np.pi * times / 4.3 + 1.0)], axis=1)).astype(int)
    writer = cv2.VideoWriter(str(out_dir / "demo.mp4"), cv2.CAP_FFMPEG, cv2.VideoWriter_fourcc(*"mp4v"),
                             FPS, (WIDTH, HEIGHT))
    if not writer.isOpened():
        raise SystemExit("cannot write demo.mp4")
    boxes, hidden = [], []
    try:
        for (cx, cy, scale), (dx, dy) in zip(path, drift):
            top, left = DRIFT - dy, DRIFT - dx
            frame = background[top:top + HEIGHT, left:left + WIDTH].copy()
            box = paste_sprite(frame, sprite, mask, cx, cy, scale)
            post_left = POST_X + dx
            frame[:, post_left:post_left + POST_W] = post[top:top + HEIGHT]
            writer.write(frame)
            boxes.append(box)
            overlap = max(0.0, min(box[0] + box[2], post_left + POST_W) - max(box[0], post_left))
            hidden.append(overlap / box[2])
    finally:
        writer.release()
    lines = [",".join(f"{v:.1f}" for v in box) for box in boxes]
    (out_dir / "demo_groundtruth.txt").write_text("\n".join(lines) + "\n")
    (out_dir / "demo_roi.txt").write_text(",".join(str(round(v)) for v in boxes[0]) + "\n")
    report_occlusion(np.array(hidden))
    return boxes


def render_wide(out_dir: Path) -> list[tuple[float, float, float, float]]:
    """Write demo_wide.mp4 and demo_wide_groundtruth.txt into ``out_dir``; return the boxes. The
    scene stands still (a fixed wide camera), so the clip compresses well."""
    rng = np.random.default_rng(WIDE_SEED)
    scene = make_background(rng, scale=2)
    top, left = (scene.shape[0] - WIDE_HEIGHT) // 2, (scene.shape[1] - WIDE_WIDTH) // 2
    background = scene[top:top + WIDE_HEIGHT, left:left + WIDE_WIDTH]
    sprite, mask = make_sprite()
    times = np.arange(int(WIDE_SECONDS * FPS)) / FPS
    writer = cv2.VideoWriter(str(out_dir / "demo_wide.mp4"), cv2.CAP_FFMPEG, cv2.VideoWriter_fourcc(*"mp4v"),
                             FPS, (WIDE_WIDTH, WIDE_HEIGHT))
    if not writer.isOpened():
        raise SystemExit("cannot write demo_wide.mp4")
    boxes = []
    try:
        for cx, cy, scale in catmull_rom(times, WIDE_KEYFRAMES):
            frame = background.copy()
            boxes.append(paste_sprite(frame, sprite, mask, cx, cy, scale))
            writer.write(frame)
    finally:
        writer.release()
    lines = [",".join(f"{v:.1f}" for v in box) for box in boxes]
    (out_dir / "demo_wide_groundtruth.txt").write_text("\n".join(lines) + "\n")
    return boxes


def report_occlusion(hidden: np.ndarray) -> None:
    """Print the occluded frame ranges and check the subject goes behind the post exactly once."""
    partly = np.flatnonzero(hidden > 0)
    fully = np.flatnonzero(hidden >= 0.999)
    if partly.size == 0 or fully.size == 0 or np.any(np.diff(partly) != 1):
        raise SystemExit("the subject must pass fully behind the post exactly once")
    print(f"partly hidden: frames {partly[0]}-{partly[-1]}; fully hidden: frames {fully[0]}-{fully[-1]}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent,
                        help="folder to write into (default: this folder)")
    out = parser.parse_args().out
    render(out)
    render_wide(out)


if __name__ == "__main__":
    main()
