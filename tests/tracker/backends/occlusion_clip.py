"""A clip rendered from real footage in which the subject hides behind a cover among look-alikes."""
import itertools

import cv2
import numpy as np

from tracker.runtime.appearance import AppearanceModel, cut_patch
from tracker.evaluation.datasets import load_sequence


def shared_frame(shared_data, name: str, index: int) -> tuple[np.ndarray, tuple[float, ...]]:
    """Frame ``index`` of a shared sequence and its true box."""
    sequence = load_sequence(shared_data / "sequences" / name)
    return next(itertools.islice(sequence.frames(), index, None)), sequence.groundtruth[index]


def lookalike_occlusion(shared_data, frames: int = 100, side: int = 48, hidden: tuple[int, int] = (30, 60)):
    """Real footage rendered into a clip: a face (otb_girl's) moving right at 3 px a frame over a sea
    (otb_surfer), hidden behind a patch of vot_bag for 30 frames while it moves on, past the four
    patches of other footage most like it to pixel NCC within 0.35-0.55. Returns the frames, the
    true boxes and which frames the face is fully hidden in."""
    sea = cv2.resize(shared_frame(shared_data, "otb_surfer", 10)[0], (400, 300), interpolation=cv2.INTER_AREA)
    girl, box = shared_frame(shared_data, "otb_girl", 0)
    x, y, w, h = (round(v) for v in box)
    face = cv2.resize(cv2.getRectSubPix(girl, (max(w, h),) * 2, (x + w // 2, y + h // 2)), (side, side))
    look = AppearanceModel(face, (0, 0, side, side))
    rng = np.random.default_rng(0)
    alikes = []
    for name, index in (("vot_bag", 50), ("otb_crossing", 30), ("vot15_ball1", 20), ("otb_girl", 250)):
        image = shared_frame(shared_data, name, index)[0]
        for _ in range(400):
            size = int(rng.uniform(0.5, 1.5) * min(image.shape[:2]) / 4)
            px, py = rng.integers(0, image.shape[1] - size), rng.integers(0, image.shape[0] - size)
            patch = cv2.resize(image[py:py + size, px:px + size], (side, side), interpolation=cv2.INTER_AREA)
            likeness = look.similarity(cut_patch(patch, (0, 0, side, side)))
            if 0.35 <= likeness <= 0.55:
                alikes.append((likeness, patch))
    alikes.sort(key=lambda found: -found[0])
    boxes = [(40.0 + 3.0 * i, 126.0 + 25.0 * np.sin(i / 15.0), float(side), float(side)) for i in range(frames)]
    x_hidden = boxes[hidden[0]][0]
    for (_, patch), (dx, dy) in zip(alikes, ((0.3, -1.5), (0.3, 1.5), (1.6, -1.5), (1.6, 1.5))):
        px, py = int(x_hidden + dx * side), int(126 + dy * side)
        sea[py:py + side, px:px + side] = patch
    inside = boxes[hidden[0]:hidden[1]]
    x0, x1 = int(min(b[0] for b in inside)) - 4, int(max(b[0] for b in inside)) + side + 4
    y0, y1 = int(min(b[1] for b in inside)) - 4, int(max(b[1] for b in inside)) + side + 4
    cover = cv2.resize(shared_frame(shared_data, "vot_bag", 150)[0], (400, 300))[y0:y1, x0:x1]
    images = []
    for bx, by, _, _ in boxes:
        image = sea.copy()
        image[round(by):round(by) + side, round(bx):round(bx) + side] = face
        image[y0:y1, x0:x1] = cover
        images.append(image)
    fully_hidden = [x0 <= b[0] and b[0] + side <= x1 and y0 <= b[1] and b[1] + side <= y1 for b in boxes]
    return images, boxes, fully_hidden
