"""The DSST-style scale ladder: a subject zoomed by whole steps is found at that step."""
import cv2
import numpy as np
import pytest

from tracker.backends.scale_estimator import ScaleEstimator
from tracker.evaluation.synthetic import texture


def zoomed(image: np.ndarray, factor: float) -> np.ndarray:
    """``image`` magnified by ``factor`` about its centre, same size."""
    h, w = image.shape[:2]
    matrix = cv2.getRotationMatrix2D(((w - 1) / 2, (h - 1) / 2), 0.0, factor)
    return cv2.warpAffine(image, matrix, (w, h), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT)


@pytest.mark.parametrize("steps", [0, 2, -3])
def test_a_subject_zoomed_by_whole_steps_is_found_there(steps):
    image = texture(200, 200, np.random.default_rng(3), cell=6, contrast=0.8)
    centre, subject = (99.5, 99.5), np.array([60.0, 40.0])
    estimator = ScaleEstimator((60.0, 40.0), scales=17, step=1.03)
    estimator.learn(estimator.spectrum(estimator.samples(image, centre, subject)), rate=1.0)
    grown = zoomed(image, 1.03**steps)
    assert estimator.best_step(estimator.spectrum(estimator.samples(grown, centre, subject))) == steps


def test_a_large_subject_is_sampled_at_the_ladders_small_size():
    estimator = ScaleEstimator((400.0, 300.0))
    image = texture(700, 900, np.random.default_rng(4), cell=12, contrast=0.8)
    samples = estimator.samples(image, (450.0, 350.0), np.array([400.0, 300.0]))
    width, height = estimator.sample_px
    assert samples.shape[0] == 17 and width * height <= 2 * 512
