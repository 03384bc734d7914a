"""One-warp window resampling, shared by the dcf and NanoTrack crops."""
import numpy as np
import pytest

from tracker.runtime.crops import resample_window


@pytest.mark.parametrize("center, size", [((40.0, 30.0), (50.0, 50.0)), ((50.3, 37.8), (80.0, 40.0)),
                                          ((20.5, 20.5), (20.0, 20.0))])
def test_window_crop_samples_the_window_it_is_given(center: tuple[float, float], size: tuple[float, float]) -> None:
    """On a plane x + 3 y (which bilinear sampling reproduces exactly), each output pixel holds the
    value at its own centre within the window; pixel i of the frame is centred on coordinate i."""
    ys, xs = np.mgrid[0:80, 0:100].astype(np.float32)
    plane = xs + 3 * ys
    out = (16, 12)
    patch = resample_window(plane, center, size, out)
    u = (np.arange(out[0]) + 0.5) / out[0] - 0.5
    v = (np.arange(out[1]) + 0.5) / out[1] - 0.5
    expected = (center[0] + u[None, :] * size[0]) + 3 * (center[1] + v[:, None] * size[1])
    np.testing.assert_allclose(patch, expected, atol=0.05)


def test_outside_the_image_is_replicated_or_filled() -> None:
    image = np.full((10, 10), 7.0, np.float32)
    image[:, 0] = 3.0
    replicated = resample_window(image, (0.0, 4.5), (4.0, 4.0), (4, 4))
    filled = resample_window(image, (0.0, 4.5), (4.0, 4.0), (4, 4), fill=(1.0, 1.0, 1.0))
    assert replicated[0, 0] == 3.0 and filled[0, 0] == 1.0
