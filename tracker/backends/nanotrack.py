"""NanoTrack v2 (on ``cv2.dnn``) and v3 (on onnxruntime): Siamese search and anchor-free box decoding.

The two networks are NanoTrack's: a backbone (template 127 px -> 8x8 features, search 255 px ->
16x16 features) and a neck/head correlating them into a map of foreground scores and of box-side
distances (left, top, right, bottom) from each map point, stride 16 px in the search crop: 16x16
for v2, 15x15 for v3 (which ``cv2.TrackerNano`` cannot run). The post-processing is SiamBAN's: a penalty on changes of box size and aspect ratio, a
cosine window favouring small motion, and a size learning rate scaled by the peak's score.

The foreground score stays near 1 on background, so the backend's score is that score times the
subject's likeness in the backbone's own features: the cosine similarity of the template's cells
under the subject's box with the search features under the chosen box (cell 7.5 of the 16x16
search features is the crop's centre, 3.5 of the 8x8 template's), relative to its running typical
value. It reuses the features of the search already made: no extra network pass. Before the
subject tracker restarts the backend on a template match, ``likeness`` scores that box the same way
(one backbone pass, only then).
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import cv2
import numpy as np

from tracker.backends.model_files import find_model_file
from tracker.backends.onnx_sessions import DEFAULT_THREADS, OnnxNetwork
from tracker.runtime.boxes import Box, from_center
from tracker.runtime.crops import resample_window

EXEMPLAR_SIZE = 127  # template crop side, pixels
INSTANCE_SIZE = 255  # search crop side, pixels
STRIDE = 16  # search-crop pixels per score-map cell
SCORE_SIZE = 16  # v2's score map side (its head only accepts a 16x16 search feature map)
V3_SCORE_SIZE = 15  # v3's score map side
SEARCH_FEATURES = 16  # the backbone's feature map side for a search crop
TEMPLATE_FEATURES = 8  # the backbone's feature map side for a template crop
TEMPLATE_MIDDLE = ((TEMPLATE_FEATURES - 1) / 2, (TEMPLATE_FEATURES - 1) / 2)  # its centre, in cells (col, row)
MIN_SIZE = 10.0  # smallest box side kept, pixels


@dataclass(frozen=True)
class NanoTrackParams:
    """Tracking hyperparameters: the published NanoTrack v2 ones, plus our motion prediction."""

    window_influence: float = 0.490  # weight of the cosine window against the penalised score
    penalty_k: float = 0.150  # strength of the size / aspect-ratio change penalty
    size_lr: float = 0.385  # size learning rate at score 1
    context_amount: float = 0.5  # context added around the box, in units of (w + h)
    swap_rb: bool = False  # the networks were trained on BGR crops (OpenCV's TrackerNano swaps)
    velocity_gain: float = 1.0  # search centre = last centre + gain x last frame's motion (0: last centre)
    # Size calibration at init: the network's box for the given subject on the first frame, from the
    # centre and shifted by +-calibration_shift of the box each way, against the given size; the
    # output sizes are corrected by that ratio to the power calibration_strength (0: off), clipped.
    calibration_strength: float = 0.5
    calibration_shift: float = 0.15
    calibration_limits: tuple[float, float] = (0.7, 1.4)
    # The score's likeness factor: the deep-feature likeness over its running typical value, which
    # follows frames at likeness_learn_above of it or more at likeness_rate (as dcf's response peak),
    # so it does not sink to the background's level. The factor ramps from 0 at likeness_zero of the
    # typical value (background boxes there sat just over the confidence gate) to 1 at likeness_full
    # of it or more (the subject's own frame-to-frame scatter; at 1.0 it cost AUC, docs/tracker-lab.md).
    likeness_rate: float = 0.05
    likeness_learn_above: float = 0.6
    likeness_full: float = 0.75
    likeness_zero: float = 0.5
    # ``anchor_likeness``'s reference: the typical likeness as it stands this many frames after a start,
    # then held, so that a box settled on something else cannot drag it down (the running value can).
    reference_frames: int = 10


#: The reference tracker's settings for v3 (SiamTrackers), without our motion prediction or size
#: calibration, which were tuned on five clips for v2.
V3_PARAMS = NanoTrackParams(window_influence=0.455, penalty_k=0.138, size_lr=0.348, velocity_gain=0.0,
                            calibration_strength=0.0)
#: NanoTrack v3 inside ``nanovit``: half the last frame's motion ahead and a weaker cosine window, chosen
#: on the mean over all 19 shared sequences with VitTrack's box averaged in (docs/tracker-lab.md).
NANOVIT_PARAMS = replace(V3_PARAMS, window_influence=0.40, velocity_gain=0.5)


def nanotrack_model_files(model_dir: str | Path | None, version: str = "v2") -> tuple[Path, Path]:
    """NanoTrack's backbone and neck/head ONNX files in ``model_dir`` (or its ``nanotrack_v2/`` or
    ``nanotrack_v3/``): the two versions' files have the same names, so the folder tells them apart."""
    what = "NanoTrack" if version == "v2" else f"NanoTrack {version}"
    if model_dir is None:
        raise FileNotFoundError(f"{what} needs its model files: pass a model directory (--model-dir, or "
                                "model_dir= in Python) holding nanotrack_backbone*.onnx and nanotrack_head*.onnx")
    backbone = find_model_file(model_dir, f"nanotrack_{version}", "nanotrack_backbone*.onnx", what)
    head = find_model_file(model_dir, f"nanotrack_{version}", "nanotrack_head*.onnx", what)
    return backbone, head


def load_nanotrack_networks(model_dir: str | Path | None) -> tuple[cv2.dnn.Net, cv2.dnn.Net]:
    """The backbone and neck/head networks from ``model_dir``, each checked by one run on blank crops.

    A file that is no ONNX network, or not the network its name says (the two swapped, or the same
    network twice), raises ``ValueError`` naming it, here rather than as an OpenCV error mid-run.
    """
    backbone_path, head_path = nanotrack_model_files(model_dir)
    backbone = _read_network(backbone_path, "backbone")
    template = _backbone_features(backbone, backbone_path, EXEMPLAR_SIZE, TEMPLATE_FEATURES)
    search = _backbone_features(backbone, backbone_path, INSTANCE_SIZE, SEARCH_FEATURES)
    head = _read_network(head_path, "neck/head")
    _check_head(head, head_path, template, search)
    return backbone, head


def _read_network(path: Path, role: str) -> cv2.dnn.Net:
    """The ONNX network in ``path``; ValueError naming the file when OpenCV cannot read it."""
    try:
        net = cv2.dnn.readNet(str(path))
    except cv2.error:
        net = None
    if net is None or net.empty():
        raise ValueError(f"NanoTrack {role} {path}: not a readable ONNX network (damaged or another file?)")
    return net


def _backbone_features(net: cv2.dnn.Net, path: Path, crop: int, side: int) -> np.ndarray:
    """The backbone's features of a blank ``crop`` px crop; ValueError naming ``path`` unless they
    are ``side`` x ``side`` maps, as NanoTrack's backbone gives."""
    try:
        net.setInput(np.zeros((1, 3, crop, crop), np.float32))
        features = net.forward()
    except cv2.error:
        features = None
    if features is None or features.ndim != 4 or features.shape[2:] != (side, side):
        raise ValueError(f"NanoTrack backbone {path}: not NanoTrack's backbone (a {crop} px crop must give "
                         f"{side}x{side} features; is it the neck/head file?)")
    return features


def _check_head(net: cv2.dnn.Net, path: Path, template: np.ndarray, search: np.ndarray) -> None:
    """ValueError naming ``path`` unless the network takes the backbone's template and search features
    (``input1``, ``input2``) and gives the score and box maps (``output1``, ``output2``)."""
    try:
        net.setInput(template, "input1")
        net.setInput(search, "input2")
        cls, loc = net.forward(["output1", "output2"])
        shapes = (cls.shape, loc.shape)
    except cv2.error:
        shapes = None
    if shapes != ((1, 2, SCORE_SIZE, SCORE_SIZE), (1, 4, SCORE_SIZE, SCORE_SIZE)):
        raise ValueError(f"NanoTrack neck/head {path}: not NanoTrack's neck/head network (it must take the "
                         "backbone's template and search features; is it a second backbone?)")


class CvNanoNetworks:
    """NanoTrack v2's two networks on ``cv2.dnn``: backbone features, then the head's maps."""

    score_size = SCORE_SIZE

    def __init__(self, model_dir: str | Path | None) -> None:
        self._backbone, self._head = load_nanotrack_networks(model_dir)

    def features(self, blob: np.ndarray) -> np.ndarray:
        self._backbone.setInput(blob)
        return self._backbone.forward()

    def set_template(self, features: np.ndarray) -> None:
        self._head.setInput(features, "input1")

    def head(self, features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The (1, 2, S, S) background/foreground logits and (1, 4, S, S) box sides for search features."""
        self._head.setInput(features, "input2")
        cls, loc = self._head.forward(["output1", "output2"])
        return cls, loc


class OrtNanoNetworks:
    """NanoTrack v3's two networks on onnxruntime, each checked on loading (``ValueError`` naming a
    file that is not the network its name says). The backbone file declares 255 px crops, which
    onnxruntime holds it to, so the 127 px template crop (once per start) goes through ``cv2.dnn``,
    which runs the same file at any size (equal features to 1e-5 on a 255 px crop)."""

    score_size = V3_SCORE_SIZE

    def __init__(self, model_dir: str | Path | None, threads: int = DEFAULT_THREADS, channels: int = 96) -> None:
        backbone, head = nanotrack_model_files(model_dir, "v3")
        self._backbone = OnnxNetwork(backbone, "NanoTrack v3 backbone", {"input": (1, 3, INSTANCE_SIZE, INSTANCE_SIZE)},
                                     {"output": (1, channels, SEARCH_FEATURES, SEARCH_FEATURES)}, threads)
        maps = (V3_SCORE_SIZE, V3_SCORE_SIZE)
        self._head = OnnxNetwork(head, "NanoTrack v3 neck/head",
                                 {"input1": (1, channels, TEMPLATE_FEATURES, TEMPLATE_FEATURES),
                                  "input2": (1, channels, SEARCH_FEATURES, SEARCH_FEATURES)},
                                 {"output1": (1, 2, *maps), "output2": (1, 4, *maps)}, threads)
        self._template = np.zeros((1, channels, TEMPLATE_FEATURES, TEMPLATE_FEATURES), np.float32)
        self._template_backbone = _read_network(backbone, "v3 backbone")
        _backbone_features(self._template_backbone, backbone, EXEMPLAR_SIZE, TEMPLATE_FEATURES)

    def features(self, blob: np.ndarray) -> np.ndarray:
        if blob.shape[2] == INSTANCE_SIZE:
            return self._backbone.run(input=blob)["output"]
        self._template_backbone.setInput(blob)
        return self._template_backbone.forward()

    def set_template(self, features: np.ndarray) -> None:
        self._template = features

    def head(self, features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        out = self._head.run(input1=self._template, input2=features)
        return out["output1"], out["output2"]


def hanning_window(size: int) -> np.ndarray:
    """The ``size`` x ``size`` cosine (Hann) window, 1 near the centre and 0 on the border."""
    hann = np.hanning(size)
    return np.outer(hann, hann).astype(np.float32)


def grid_offsets(size: int = SCORE_SIZE, stride: int = STRIDE) -> np.ndarray:
    """Each score-map point's offset from the search crop's centre, crop pixels (1-D, per axis)."""
    return ((np.arange(size) - size // 2) * stride).astype(np.float32)


def foreground_score(cls: np.ndarray) -> np.ndarray:
    """Softmax foreground probability from the head's (2, H, W) background/foreground logits."""
    logits = cls - cls.max(axis=0, keepdims=True)
    odds = np.exp(logits)
    return odds[1] / odds.sum(axis=0)


def decode_boxes(loc: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Boxes (cx, cy, w, h) per map point from the (4, H, W) side distances (l, t, r, b).

    Centres are relative to the search crop's centre; all in crop pixels; shape (4, H, W).
    """
    gx, gy = offsets[None, :], offsets[:, None]
    left, top, right, bottom = loc
    x1, y1, x2, y2 = gx - left, gy - top, gx + right, gy + bottom
    return np.stack([(x1 + x2) / 2, (y1 + y2) / 2, x2 - x1, y2 - y1])


def padded_size(w: np.ndarray | float, h: np.ndarray | float) -> np.ndarray | float:
    """SiamRPN's scale measure: the side of the square with the context-padded box's area."""
    pad = (w + h) / 2
    return np.sqrt((w + pad) * (h + pad))


def change_penalty(w: np.ndarray, h: np.ndarray, target_w: float, target_h: float, k: float) -> np.ndarray:
    """``exp(-k (r s - 1))`` where s, r >= 1 are the changes of scale and aspect ratio."""
    scale = padded_size(w, h) / padded_size(target_w, target_h)
    ratio = (target_w / target_h) / (w / np.maximum(h, 1e-6))
    scale = np.maximum(scale, 1 / scale)
    ratio = np.maximum(ratio, 1 / ratio)
    return np.exp(-(ratio * scale - 1) * k)


def select_peak(score: np.ndarray, boxes: np.ndarray, target_size: np.ndarray, window: np.ndarray,
                params: NanoTrackParams) -> tuple[tuple[int, int], float]:
    """The (row, col) maximising the penalised, windowed score, and the change penalty there.

    ``boxes`` is :func:`decode_boxes`'s output and ``target_size`` the current (w, h), both in
    search-crop pixels.
    """
    penalty = change_penalty(boxes[2], boxes[3], float(target_size[0]), float(target_size[1]), params.penalty_k)
    pscore = penalty * score * (1 - params.window_influence) + window * params.window_influence
    row, col = np.unravel_index(int(np.argmax(pscore)), pscore.shape)
    return (int(row), int(col)), float(penalty[row, col])


def sample_cells(features: np.ndarray, center: tuple[float, float], cells: tuple[int, int]) -> np.ndarray:
    """The (C, rows, cols) block of a (C, H, W) feature map centred on ``center`` = (col, row), in cell
    units (fractional: bilinear; clamped to the map), with ``cells`` = (cols, rows)."""
    _, height, width = features.shape
    cols, rows = cells
    xs = np.clip(center[0] + np.arange(cols) - (cols - 1) / 2, 0, width - 1)
    ys = np.clip(center[1] + np.arange(rows) - (rows - 1) / 2, 0, height - 1)
    x0, y0 = np.minimum(xs.astype(int), width - 2), np.minimum(ys.astype(int), height - 2)
    fx, fy = (xs - x0)[None, :], (ys - y0)[:, None]
    top = features[:, y0][:, :, x0] * (1 - fx) + features[:, y0][:, :, x0 + 1] * fx
    bottom = features[:, y0 + 1][:, :, x0] * (1 - fx) + features[:, y0 + 1][:, :, x0 + 1] * fx
    return top * (1 - fy) + bottom * fy


def cosine_likeness(a: np.ndarray, b: np.ndarray) -> float:
    """The cosine similarity of two equally shaped feature blocks, clipped to 0..1 (0 when either is 0)."""
    norm = float(np.linalg.norm(a) * np.linalg.norm(b))
    return float(np.clip(np.vdot(a, b) / norm, 0.0, 1.0)) if norm > 0 else 0.0


def likeness_at(subject: np.ndarray, features: np.ndarray, cell: tuple[float, float]) -> float:
    """The subject's template cells (C, rows, cols) against ``features`` (C, H, W) sampled as many
    cells around ``cell`` (col, row), 0..1."""
    return cosine_likeness(subject, sample_cells(features, cell, (subject.shape[2], subject.shape[1])))


def crop_square(frame: np.ndarray, cx: float, cy: float, side: float, out: int,
                fill: tuple[float, float, float]) -> np.ndarray:
    """The square of ``side`` image pixels centred on (cx, cy), resampled to ``out`` x ``out``.

    Centres are continuous coordinates (a pixel i spans [i, i + 1]); outside the frame is ``fill``.
    """
    return resample_window(frame, (cx - 0.5, cy - 0.5), (side, side), (out, out), fill)


@dataclass(frozen=True)
class Peak:
    """The chosen score-map point: box (cx, cy, w, h) in image pixels, its score and penalty, and
    where its box's centre lies on the search crop's backbone features (col, row), in cells."""

    box: tuple[float, float, float, float]
    score: float
    penalty: float
    features: np.ndarray  # (C, H, W)
    cell: tuple[float, float]

    def likeness(self, subject: np.ndarray) -> float:
        """The search features under the box against the subject's template cells (C, rows, cols), 0..1."""
        return likeness_at(subject, self.features, self.cell)


class NanoTrackBackend:
    """NanoTrack v2 or v3 (``TrackingBackend``): score = foreground probability of the chosen peak
    times its deep-feature likeness to the subject relative to the likeness's running typical value.
    ``networks`` defaults to v2's on ``cv2.dnn`` (:class:`OrtNanoNetworks` runs v3)."""

    def __init__(self, model_dir: str | Path | None, params: NanoTrackParams | None = None,
                 networks: CvNanoNetworks | OrtNanoNetworks | None = None, name: str = "nanotrack") -> None:
        self.name = name
        self.params = params or NanoTrackParams()
        self._networks = networks or CvNanoNetworks(model_dir)
        self._window = hanning_window(self._networks.score_size)
        self._offsets = grid_offsets(self._networks.score_size)
        self._center = np.zeros(2)
        self._size = np.ones(2)
        self._velocity = np.zeros(2)  # the centre's motion over the last frame, pixels
        self._calibration = np.ones(2)  # given size / the network's size for the subject (w, h)
        self._fill = (0.0, 0.0, 0.0)
        self._subject_features = np.zeros((1, 1, 1), np.float32)  # the template's cells under the subject
        self._typical_likeness = 0.0
        self._reference_likeness = 0.0  # the typical likeness reference_frames after the start, held
        self._last_likeness = 0.0  # the last box's deep likeness to the subject
        self._updates = 0  # since the last start
        self._ready = False

    def init(self, frame: np.ndarray, box: Box) -> None:
        x, y, w, h = (float(v) for v in box)
        self._center = np.array([x + w / 2, y + h / 2])
        self._size = np.array([max(w, 1.0), max(h, 1.0)])
        self._velocity = np.zeros(2)
        self._fill = tuple(float(v) for v in cv2.mean(frame)[:3])
        side = self._context_side()
        template = self._template(frame, self._center, side)
        self._networks.set_template(template)
        cells = np.clip(np.round(self._size * EXEMPLAR_SIZE / side / STRIDE), 1, TEMPLATE_FEATURES).astype(int)
        self._subject_features = sample_cells(template[0], TEMPLATE_MIDDLE, (int(cells[0]), int(cells[1])))
        self._typical_likeness = 0.0
        self._updates = 0
        self._ready = True
        self._calibration = self._measure_size_calibration(frame)
        self._size = self._size / self._calibration  # tracked in the network's own size

    def update(self, frame: np.ndarray) -> tuple[Box | None, float]:
        if not self._ready:
            raise RuntimeError(f"{self.name}: update() before init()")
        predicted = self._center + self.params.velocity_gain * self._velocity
        peak = self._search(frame, predicted, INSTANCE_SIZE / EXEMPLAR_SIZE * self._context_side())
        lr = peak.penalty * peak.score * self.params.size_lr  # a doubtful peak changes the size less
        size = (1 - lr) * self._size + lr * np.array(peak.box[2:])
        frame_size = np.array(frame.shape[1::-1], dtype=float)
        center = np.clip(peak.box[:2], 0, frame_size)
        self._velocity = center - self._center
        self._center = center
        self._size = np.clip(size, MIN_SIZE, frame_size)
        (cx, cy), (w, h) = self._center, np.minimum(self._size * self._calibration, frame_size)
        self._last_likeness = peak.likeness(self._subject_features)
        score = np.clip(peak.score, 0, 1) * self._relative_likeness(self._last_likeness)
        self._updates += 1
        if self._updates <= self.params.reference_frames:
            self._reference_likeness = self._typical_likeness
        return from_center(float(cx), float(cy), float(w), float(h)), float(score)

    def anchor_likeness(self) -> float:
        """The last box's deep likeness to the subject over its typical value in the first
        ``reference_frames`` after the start, held from then on (1 before any update). Unlike the
        score's running reference, it does not follow a box that has settled on a cover or on
        background, so it tells the subject tracker whether the box still holds the subject."""
        return self._last_likeness / self._reference_likeness if self._reference_likeness > 0 else 1.0

    @property
    def size_calibration(self) -> np.ndarray:
        """The output sizes' correction (w, h) found at init: given size / the network's, softened."""
        return self._calibration.copy()

    def _measure_size_calibration(self, frame: np.ndarray) -> np.ndarray:
        """How the given box's (w, h) relate to what the network sees as the subject's box on the
        frame it was given on (a per-subject bias: one subject's box comes out too wide, another's
        too short), softened by ``calibration_strength``; ones when that is 0."""
        p = self.params
        if p.calibration_strength <= 0:
            return np.ones(2)
        shifts = p.calibration_shift * np.array([[0, 0], [1, 0], [-1, 0], [0, 1], [0, -1]]) * self._size
        side = INSTANCE_SIZE / EXEMPLAR_SIZE * self._context_side()
        sizes = np.array([self._search(frame, self._center + shift, side).box[2:] for shift in shifts])
        log_ratio = np.mean(np.log(self._size / np.maximum(sizes, 1.0)), axis=0)
        return np.clip(np.exp(p.calibration_strength * log_ratio), *p.calibration_limits)

    def _relative_likeness(self, likeness: float) -> float:
        """The score's likeness factor, 0..1: ``likeness`` over its running typical value, ramped from
        0 at ``likeness_zero`` to 1 at ``likeness_full`` (1 on the first frame). Only frames at
        ``likeness_learn_above`` of the typical value or more move it, as ``dcf`` does with its response
        peak, so it does not sink to the background's level while the subject is gone."""
        p = self.params
        if self._typical_likeness <= 0.0:
            self._typical_likeness = likeness
        relative = float(np.clip(likeness / max(self._typical_likeness, 1e-6), 0.0, 1.0))
        if relative >= p.likeness_learn_above:
            rate = p.likeness_rate * relative
            self._typical_likeness = (1 - rate) * self._typical_likeness + rate * likeness
        return float(np.clip((relative - p.likeness_zero) / (p.likeness_full - p.likeness_zero), 0.0, 1.0))

    def likeness(self, frame: np.ndarray, box: Box) -> float:
        """``box``'s deep-feature likeness to the subject over its running typical value (1 while that
        is unknown): one backbone pass on a template crop centred on ``box``, sized as at init."""
        if self._typical_likeness <= 0.0:
            return 1.0
        x, y, w, h = (float(v) for v in box)
        template = self._template(frame, (x + w / 2, y + h / 2), self._context_side((max(w, 1.0), max(h, 1.0))))
        return likeness_at(self._subject_features, template[0], TEMPLATE_MIDDLE) / self._typical_likeness

    def _context_side(self, size: tuple[float, float] | None = None) -> float:
        """Side of the template crop: the box (of ``size``, else the tracked one) padded by
        ``context_amount`` (w + h), squared."""
        w, h = self._size if size is None else size
        pad = self.params.context_amount * (w + h)
        return float(np.sqrt((w + pad) * (h + pad)))

    def _template(self, frame: np.ndarray, center: tuple[float, float] | np.ndarray, side: float) -> np.ndarray:
        """The backbone's features of the template crop of ``side`` image pixels centred on ``center``."""
        return self._features(crop_square(frame, *center, side, EXEMPLAR_SIZE, self._fill))

    def _features(self, crop: np.ndarray) -> np.ndarray:
        if crop.ndim == 2:  # the networks take three channels
            crop = cv2.cvtColor(crop, cv2.COLOR_GRAY2BGR)
        blob = cv2.dnn.blobFromImage(crop, 1.0, swapRB=self.params.swap_rb)
        return self._networks.features(blob)

    def _search(self, frame: np.ndarray, center: np.ndarray, side: float) -> Peak:
        """The best peak in the search crop of ``side`` image pixels centred on ``center``."""
        crop = crop_square(frame, *center, side, INSTANCE_SIZE, self._fill)
        features = self._features(crop)
        cls, loc = self._networks.head(features)
        score = foreground_score(cls[0])
        boxes = decode_boxes(loc[0], self._offsets)
        scale = INSTANCE_SIZE / side  # crop pixels per image pixel
        (row, col), penalty = select_peak(score, boxes, self._size * scale, self._window, self.params)
        bcx, bcy, bw, bh = boxes[:, row, col]
        middle = (SEARCH_FEATURES - 1) / 2  # the search features' cell at the crop's centre
        cell = (middle + bcx / STRIDE, middle + bcy / STRIDE)
        box = (float(center[0] + bcx / scale), float(center[1] + bcy / scale), float(bw / scale), float(bh / scale))
        return Peak(box, float(score[row, col]), penalty, features[0], cell)
