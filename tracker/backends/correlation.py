"""Discriminative correlation filters learnt in the Fourier domain (multi-channel, linear kernel).

``TranslationFilter`` answers "where did the patch move" on a 2-D cell grid; ``ScaleFilter``
answers "by how much did it grow" over a 1-D stack of scale samples. Both keep running
averages of the filter's numerator and denominator, as in MOSSE/DSST.
"""
from __future__ import annotations

import numpy as np
from scipy import fft


def gaussian_peak(shape: tuple[int, ...], sigma: float) -> np.ndarray:
    """A Gaussian of ``sigma`` cells peaking at index 0 of every axis, wrapped around."""
    grids = np.meshgrid(*[_wrapped_offsets(n) for n in shape], indexing="ij")
    return np.exp(-0.5 * sum(g.astype(np.float64) ** 2 for g in grids) / sigma**2)


def running_average(old: np.ndarray | None, new: np.ndarray, rate: float) -> np.ndarray:
    """``new`` when there is no ``old`` or ``rate`` >= 1 (a restart), else ``(1 - rate) old + rate new``."""
    if old is None or rate >= 1.0:
        return new
    return (1 - rate) * old + rate * new


def _wrapped_offsets(n: int) -> np.ndarray:
    index = np.arange(n)
    return np.where(index <= n // 2, index, index - n)


class TranslationFilter:
    """A correlation filter over ``(rows, cols, channels)`` cell features."""

    def __init__(self, shape: tuple[int, int], sigma: float, regularisation: float = 1e-3) -> None:
        rows, cols = shape
        self.shape = shape
        self._label = fft.rfft2(gaussian_peak(shape, sigma).astype(np.float32))[..., None]
        self._window = (np.hanning(rows)[:, None] * np.hanning(cols)[None, :])[..., None].astype(np.float32)
        self._centred = np.fft.fftshift(np.arange(rows * cols).reshape(shape))  # what fftshift gathers, cheaper
        self._regularisation = regularisation
        self._numerator: np.ndarray | None = None
        self._denominator: np.ndarray | None = None

    def learn(self, features: np.ndarray, rate: float) -> None:
        """Fold a training sample centred on the target into the filter (``rate`` 1 restarts)."""
        spectrum = fft.rfft2(features * self._window, axes=(0, 1))
        self._numerator = running_average(self._numerator, self._label * np.conj(spectrum), rate)
        self._denominator = running_average(self._denominator, np.sum(np.abs(spectrum) ** 2, axis=2), rate)

    def respond(self, features: np.ndarray) -> np.ndarray:
        """The response over the grid, zero displacement at the centre (``shape // 2``)."""
        if self._numerator is None:
            raise RuntimeError("TranslationFilter.respond() before learn()")
        spectrum = fft.rfft2(features * self._window, axes=(0, 1))
        product = np.sum(self._numerator * spectrum, axis=2) / (self._denominator + self._regularisation)
        return fft.irfft2(product, s=self.shape).take(self._centred)


class ScaleFilter:
    """A 1-D correlation filter over ``(scales, dims)`` samples, the middle scale being today's."""

    def __init__(self, scales: int, sigma: float, regularisation: float = 1e-2) -> None:
        self._scales = scales
        self._label = fft.rfft(gaussian_peak((scales,), sigma).astype(np.float32))[:, None]
        self._window = np.hanning(scales + 2)[1:-1, None].astype(np.float32)
        self._regularisation = regularisation
        self._numerator: np.ndarray | None = None
        self._denominator: np.ndarray | None = None

    def spectrum(self, samples: np.ndarray) -> np.ndarray:
        """The windowed samples' spectrum over the scales, which ``learn`` and ``respond`` take
        (computed once where both use the same samples)."""
        return fft.rfft(samples * self._window, axis=0)

    def learn(self, spectrum: np.ndarray, rate: float) -> None:
        """Fold the spectrum of samples taken around the current scale into the filter (``rate`` 1
        restarts)."""
        self._numerator = running_average(self._numerator, self._label * np.conj(spectrum), rate)
        self._denominator = running_average(self._denominator, np.sum(np.abs(spectrum) ** 2, axis=1), rate)

    def respond(self, spectrum: np.ndarray) -> np.ndarray:
        """The response per scale sample of a spectrum, zero change at index 0 (wrapped like the label)."""
        if self._numerator is None:
            raise RuntimeError("ScaleFilter.respond() before learn()")
        product = np.sum(self._numerator * spectrum, axis=1) / (self._denominator + self._regularisation)
        return fft.irfft(product, n=self._scales)
