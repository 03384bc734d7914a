"""A fast correlation-filter tracker: gradient and colour cues, DSST-style scale (no model files).

Each frame: cut a window around the last position (context around the subject, resized to
a fixed cell grid) and find the displacement from the blend of the translation filter's
response and the colour model's. Every ``update_every`` frames, also find the scale from the
1-D scale filter and teach all three models at the new position, at that many times the
per-frame rates (ECO's sparse updating). The ideas are those of Staple (Bertinetto et al.,
2016), DSST (Danelljan et al., 2014) and ECO (Danelljan et al., 2017); the implementation is
our own, vectorised numpy.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from tracker.backends.colour_model import ColourModel, box_response, colour_index
from tracker.backends.correlation import TranslationFilter
from tracker.backends.features import CELL, cell_features, unit_grey
from tracker.backends.scale_estimator import ScaleEstimator
from tracker.runtime.boxes import Box, center, from_center
from tracker.runtime.crops import resample_window


@dataclass(frozen=True)
class DcfSettings:
    """Published defaults of the methods above, except where the comment says otherwise."""

    context: float = 1.5  # window = subject + context x mean side (KCF's padding; Staple used 1.0)
    window_area: float = 100.0**2  # the window is resized to about this many pixels (Staple: 150**2)
    sigma_factor: float = 1 / 16  # label width relative to the subject's size
    learning_rate: float = 0.01
    colour_rate: float = 0.04
    colour_weight: float = 0.3  # share of the colour response in the blend
    inner_padding: float = 0.2  # foreground = subject shrunk by this x mean side
    # fDSST's finer ladder (Danelljan et al., 2017): 33 samples 1.02 apart reach as far as 17 at 1.03
    # in finer steps, which scored higher over all 19 shared sequences (docs/tracker-lab.md)
    scales: int = 33
    scale_step: float = 1.02
    scale_area: float = 512.0  # scale samples are resized to about this many pixels (DSST's value)
    scale_rate: float = 0.025
    min_scale: float = 0.2
    max_scale: float = 5.0
    peak_rate: float = 0.05  # how fast the typical response peak follows confident frames
    learn_above: float = 0.4  # frames scoring lower (occluded, probably) teach the models nothing
    # Scale and learning every this many frames, at that many times the rates: a clearly faster
    # tracker whose accuracy stays within the noise of learning every frame; 3 gained little more
    # speed in the loop, 5 lost accuracy (docs/tracker-lab.md).
    update_every: int = 2

    def __post_init__(self) -> None:
        if self.update_every < 1:
            raise ValueError(f"update_every must be at least 1, got {self.update_every}")


class DcfBackend:
    """A :class:`tracker.backends.TrackingBackend`; the score is the translation filter's response
    peak relative to its running typical value (1 as usual, falling towards 0 as the subject
    is hidden or changes faster than the models learn)."""

    def __init__(self, settings: DcfSettings | None = None, name: str = "dcf") -> None:
        self.name = name
        self.settings = settings or DcfSettings()
        self._center = np.zeros(2)
        self._base_size = np.ones(2)
        self._scale = 1.0
        self._typical_peak = 0.0
        self._typical_frames = 0  # frames that moved the typical peak (its mean until 1 / peak_rate of them)
        self._translation: TranslationFilter | None = None

    def init(self, frame: np.ndarray, box: Box) -> None:
        s = self.settings
        self._center = np.array(center(box))
        self._base_size = np.array([max(box[2], 2.0), max(box[3], 2.0)])
        self._scale = 1.0
        window = self._base_size + s.context * self._base_size.mean()
        resize = np.sqrt(s.window_area / np.prod(window))
        grid = np.maximum(np.round(window * resize / CELL).astype(int), 4)  # cols, rows
        self._patch_size = (int(grid[0]) * CELL, int(grid[1]) * CELL)  # the window patch, px
        self._base_window = window
        cells_per_px = grid / window
        subject_cells = self._base_size * cells_per_px
        self._colour_box = tuple(int(max(1, 2 * round(c / 2) + 1)) for c in subject_cells)
        sigma = np.sqrt(np.prod(subject_cells)) * s.sigma_factor
        self._translation = TranslationFilter((int(grid[1]), int(grid[0])), sigma)
        self._colour = ColourModel()
        self._masks = self._colour_masks(cells_per_px * CELL)
        self._scale_estimator = ScaleEstimator(tuple(self._base_size), s.scales, s.scale_step, s.scale_area)
        self._typical_peak = 0.0
        self._typical_frames = 0
        self._frames = 0
        self._learn(self._region(frame), restart=True)

    def update(self, frame: np.ndarray) -> tuple[Box | None, float]:
        if self._translation is None:
            raise RuntimeError(f"{self.name}: update() before init()")
        s = self.settings
        patch = self._window_patch(self._region(frame))
        response = self._translation.respond(self._features(patch))
        peak = float(response.max())
        if s.colour_weight > 0:
            colour = box_response(self._colour.likelihood(colour_index(patch)), CELL, self._colour_box)
            response = (1 - s.colour_weight) * response + s.colour_weight * colour
        row, col = np.unravel_index(int(np.argmax(response)), response.shape)
        shift = np.array([col + _subcell(response[row, :], col), row + _subcell(response[:, col], row)])
        shift -= np.array([response.shape[1] // 2, response.shape[0] // 2])
        self._center = self._center + shift * CELL * (self._base_window * self._scale) / np.array(self._patch_size)
        score = self._score(peak)
        self._frames += 1
        if self._frames % s.update_every == 0:
            self._rescale_and_learn(frame, score)
        w, h = self._base_size * self._scale
        return from_center(float(self._center[0]), float(self._center[1]), float(w), float(h)), score

    def _score(self, peak: float) -> float:
        """The peak relative to its running typical value: 1 as usual, towards 0 as it collapses.
        Only frames confident enough to teach the models move the typical value, so it never
        sinks to the background's level while the subject is gone (the score would climb back).
        The typical value is the mean of the first 1 / ``peak_rate`` such peaks, then a running
        value: the first frame's peak alone, from a filter that has seen only the start frame, was
        up to four times what followed on drone and broadcast footage, so every later frame scored
        under ``learn_above`` and the models never learnt again (docs/tracker-lab.md)."""
        s = self.settings
        if self._typical_frames == 0:
            self._typical_peak = peak
        score = float(np.clip(peak / max(self._typical_peak, 1e-6), 0.0, 1.0))
        if score >= s.learn_above:
            self._typical_frames += 1
            rate = max(s.peak_rate * score, 1.0 / self._typical_frames)
            self._typical_peak = (1 - rate) * self._typical_peak + rate * peak
        return score

    def _rescale_and_learn(self, frame: np.ndarray, score: float) -> None:
        """The scale step at the new position, then (unless ``score`` is too low) the lesson."""
        s = self.settings
        region = self._region(frame)
        samples = self._scale_samples(region)
        spectrum = self._scale_estimator.spectrum(samples)
        step = self._scale_estimator.best_step(spectrum)
        if not s.min_scale <= self._scale * s.scale_step**step <= s.max_scale:
            step = 0
        self._scale *= s.scale_step**step
        if score >= s.learn_above:
            if step != 0:
                region = self._region(frame)  # the window follows the new scale
                spectrum = self._scale_estimator.spectrum(np.roll(samples, -step, axis=0))  # re-centred on it
            self._learn(region, scale_spectrum=spectrum)

    def _learn(self, region: _Region, restart: bool = False, scale_spectrum: np.ndarray | None = None) -> None:
        """Teach the three models the subject in ``region``: afresh, or at the per-frame rates
        times ``update_every`` (the frames in between teach nothing)."""
        s = self.settings
        k = s.update_every
        patch = self._window_patch(region)
        self._translation.learn(self._features(patch), 1.0 if restart else k * s.learning_rate)
        if s.colour_weight > 0:
            fg, bg = self._masks
            self._colour.learn(colour_index(patch), fg, bg, 1.0 if restart else k * s.colour_rate)
        if scale_spectrum is None:
            scale_spectrum = self._scale_estimator.spectrum(self._scale_samples(region))
        self._scale_estimator.learn(scale_spectrum, 1.0 if restart else k * s.scale_rate)

    def _region(self, frame: np.ndarray) -> _Region:
        """The window around the subject, cut once per position and scale; every patch comes from it."""
        return _Region.cut(frame, self._center, self._base_window * self._scale, np.array(self._patch_size))

    def _window_patch(self, region: _Region) -> np.ndarray:
        """The window resampled to the patch size in one bilinear warp, at under 4:1 (see ``_Region``):
        a crop then an area resize cost several times as much and scored the same (docs/tracker-lab.md), and
        averaging the region down further to keep bilinear under 2:1 scored lower on perturbed starts."""
        window = self._base_window * self._scale / region.k
        return resample_window(region.image, region.to_region(self._center), window, self._patch_size)

    def _features(self, patch: np.ndarray) -> np.ndarray:
        return cell_features(unit_grey(patch)[None])[0]

    def _scale_samples(self, region: _Region) -> np.ndarray:
        """The scale ladder's samples around the subject (see ``ScaleEstimator.samples``)."""
        return self._scale_estimator.samples(region.image, region.to_region(self._center),
                                             self._base_size * self._scale / region.k)

    def _colour_masks(self, patch_per_px: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Foreground (the subject shrunk) and background (outside it) masks of the window patch."""
        width, height = self._patch_size
        subject = self._base_size * patch_per_px
        inner = (self._base_size - self.settings.inner_padding * self._base_size.mean()) * patch_per_px
        xs = np.abs(np.arange(width) + 0.5 - width / 2.0)[None, :]
        ys = np.abs(np.arange(height) + 0.5 - height / 2.0)[:, None]
        foreground = (xs <= max(inner[0], 1.0) / 2) & (ys <= max(inner[1], 1.0) / 2)
        background = (xs > subject[0] / 2) | (ys > subject[1] / 2)
        return foreground, background


@dataclass(frozen=True)
class _Region:
    """The part of a frame a window covers, averaged down by a whole factor ``k`` when the window
    is over twice a patch's resolution (so that a large subject costs no more than a small one).
    Its pixels are the frame's own (k = 1) or exact k x k means: crops from it equal crops from
    the frame."""

    image: np.ndarray
    origin: tuple[int, int]  # the frame pixel at the region's (0, 0)
    k: int  # frame pixels per region pixel, each way

    @classmethod
    def cut(cls, frame: np.ndarray, center: np.ndarray, window: np.ndarray, patch: np.ndarray) -> _Region:
        k = max(1, int(min(window[0] / (2 * patch[0]), window[1] / (2 * patch[1]))))
        height, width = frame.shape[:2]
        (x0, x1), (y0, y1) = (_span(float(c), float(half) + 2 + k, size, k) for c, half, size in  # + bilinear reach
                              zip(center, window / 2.0, (width, height)))
        image = frame[y0:y1, x0:x1]
        if k > 1:
            image = cv2.resize(image, ((x1 - x0) // k, (y1 - y0) // k), interpolation=cv2.INTER_AREA)
        return cls(image, (x0, y0), k)

    def to_region(self, point: np.ndarray) -> tuple[float, float]:
        """A frame point in region pixel coordinates."""
        shift = (self.k - 1) / 2.0  # region pixel j is centred on frame pixel origin + j k + shift
        return ((point[0] - self.origin[0] - shift) / self.k, (point[1] - self.origin[1] - shift) / self.k)


def _span(center: float, half: float, size: int, k: int) -> tuple[int, int]:
    """Whole-pixel bounds in 0..size covering ``center`` +- ``half``, their length a multiple of k."""
    start = min(max(math.floor(center - half), 0), size - 1)
    end = min(max(math.ceil(center + half), start + 1), size)
    end = start + max(k, (end - start) // k * k)
    return (start, end) if end <= size else (max(0, size - (end - start)), size)


def _subcell(values: np.ndarray, index: int) -> float:
    """Parabolic sub-cell offset of the peak at ``index`` in ``values`` (0 at the edges)."""
    if index <= 0 or index >= len(values) - 1:
        return 0.0
    left, mid, right = values[index - 1], values[index], values[index + 1]
    curvature = left - 2 * mid + right
    return float(0.5 * (left - right) / curvature) if curvature < 0 else 0.0
