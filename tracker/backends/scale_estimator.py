"""DSST-style scale estimation: the subject's box at a ladder of scale factors, sampled to a fixed
size, described by cell features and matched by a 1-D correlation filter over the ladder.

Used by ``dcf`` for its scale (beside NanoTrack it did not help: docs/tracker-lab.md). The method is
that of DSST (Danelljan et al., 2014); the implementation is our own.
"""
from __future__ import annotations

import cv2
import numpy as np

from tracker.backends.correlation import ScaleFilter
from tracker.backends.features import CELL, cell_features, unit_grey


class ScaleEstimator:
    """Samples ``scales`` boxes ``step`` apart around today's size and learns which one is the
    subject's; ``best_step`` says how many steps the subject grew (negative: shrank)."""

    def __init__(self, subject_size: tuple[float, float], scales: int = 17, step: float = 1.03,
                 sample_area: float = 512.0) -> None:
        size = np.maximum(np.asarray(subject_size, dtype=float), 2.0)
        resize = np.sqrt(sample_area / np.prod(size))
        self.sample_px = tuple(int(v) * CELL for v in np.maximum(np.round(size * resize / CELL), 2))
        self.scales = scales
        self.step = step
        self.factors = step ** (np.arange(scales) - scales // 2)
        self._offsets = _sample_offsets(self.sample_px, self.factors)
        self._filter = ScaleFilter(scales, np.sqrt(scales) / 4)

    def samples(self, image: np.ndarray, centre: tuple[float, float], subject: np.ndarray) -> np.ndarray:
        """Features ``(scales, dims)`` of the ``subject``-sized (w, h) box around ``centre`` at every
        factor, all in ``image`` pixels (pixel i centred on i). The grey image is first averaged
        down so that the largest box is about the sample size, then every sample is cut in one
        bilinear remap at up to 1:1, free of aliasing (per-sample area resizing took twice as long
        and scored the same)."""
        grey = unit_grey(image)
        shrink = min(1.0, float(np.min(np.array(self.sample_px) / (subject * self.factors[-1]))))
        if shrink < 1.0:
            size = (max(1, round(grey.shape[1] * shrink)), max(1, round(grey.shape[0] * shrink)))
            grey = cv2.resize(grey, size, interpolation=cv2.INTER_AREA)
        ratio = np.array([grey.shape[1] / image.shape[1], grey.shape[0] / image.shape[0]])
        middle = (np.array(centre) + 0.5) * ratio - 0.5
        span = subject * ratio
        offset_x, offset_y = self._offsets
        scales, height, width = offset_x.shape
        map_x = (offset_x * np.float32(span[0]) + np.float32(middle[0])).reshape(-1, width)
        map_y = (offset_y * np.float32(span[1]) + np.float32(middle[1])).reshape(-1, width)
        samples = cv2.remap(grey, map_x, map_y, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
        return cell_features(samples.reshape(scales, height, width)).reshape(scales, -1)

    def spectrum(self, samples: np.ndarray) -> np.ndarray:
        """What ``best_step`` and ``learn`` take: the samples' spectrum over the ladder."""
        return self._filter.spectrum(samples)

    def best_step(self, spectrum: np.ndarray) -> int:
        """Steps from today's size to the best-matching sample, -scales//2 .. scales//2."""
        step = int(np.argmax(self._filter.respond(spectrum)))
        return step if step <= self.scales // 2 else step - self.scales

    def learn(self, spectrum: np.ndarray, rate: float) -> None:
        """Fold the spectrum of samples centred on the subject's size into the filter (``rate`` 1
        restarts)."""
        self._filter.learn(spectrum, rate)


def _sample_offsets(size: tuple[int, int], factors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each scale sample's pixel centres relative to the subject's centre, in subject sizes:
    x and y, each ``(scales, height, width)`` float32."""
    width, height = size
    xs = (np.arange(width) + 0.5) / width - 0.5
    ys = (np.arange(height) + 0.5) / height - 0.5
    shape = (len(factors), height, width)
    return (np.broadcast_to(factors[:, None, None] * xs[None, None, :], shape).astype(np.float32),
            np.broadcast_to(factors[:, None, None] * ys[None, :, None], shape).astype(np.float32))
