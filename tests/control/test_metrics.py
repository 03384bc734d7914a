import math

import pytest

from pipelines.control.metrics import CentringSample, summarize


def test_summary_figures():
    samples = [
        CentringSample(0.0, 0.3, 0.4, True),  # error 0.5, direction (0.6, 0.8)
        CentringSample(0.1, 0.03, 0.04, True),  # centred at 0.1 s
        CentringSample(0.2, -0.06, -0.08, False),  # 0.1 past the centre
        CentringSample(0.3, 0.0, 0.0, True),
    ]
    s = summarize(samples)
    assert s["frames"] == 4
    assert s["mean_center_error"] == pytest.approx((0.5 + 0.05 + 0.1) / 4)
    assert s["rms_center_error"] == pytest.approx(math.sqrt((0.25 + 0.0025 + 0.01) / 4))
    assert s["out_of_view"] == 0.25
    assert s["time_to_first_centre"] == pytest.approx(0.1)
    assert s["overshoot"] == pytest.approx(0.1 / 0.5)


def test_never_centred_and_started_centred():
    s = summarize([CentringSample(0.0, 0.3, 0.0, True), CentringSample(0.1, 0.2, 0.0, True)])
    assert s["time_to_first_centre"] is None and s["overshoot"] == 0.0
    s = summarize([CentringSample(0.0, 0.01, 0.0, True), CentringSample(0.1, -0.04, 0.0, True)])
    assert s["time_to_first_centre"] == 0.0 and s["overshoot"] == 0.0
    with pytest.raises(ValueError):
        summarize([])
