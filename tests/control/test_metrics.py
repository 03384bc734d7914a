import math

import pytest

from pipelines.control.metrics import OVERSHOOT_WINDOW_S, CentringSample, summarize


def test_summary_figures():
    samples = [
        CentringSample(0.0, 0.3, 0.4, True),  # error 0.5, direction (0.6, 0.8)
        CentringSample(0.1, 0.03, 0.04, True),  # centred at 0.1 s
        CentringSample(0.2, -0.06, -0.08, False),  # 0.1 past the centre
        CentringSample(0.3, 0.0, 0.0, True),
    ]
    s = summarize(samples)
    assert s["frames"] == s["frames_scored"] == 4
    assert s["mean_center_error"] == pytest.approx((0.5 + 0.05 + 0.1) / 4)
    assert s["rms_center_error"] == pytest.approx(math.sqrt((0.25 + 0.0025 + 0.01) / 4))
    assert s["out_of_view"] == 0.25
    assert s["time_to_first_centre"] == pytest.approx(0.1)
    assert s["overshoot"] == pytest.approx(0.1 / 0.5)


def test_frames_without_truth_are_left_out_of_every_figure():
    """``None`` frames (no ground truth) count in ``frames`` only; the figures are those of the rest,
    time to first centre counting from the first frame with truth."""
    scored = [CentringSample(0.2, 0.3, 0.0, True), CentringSample(0.3, 0.02, 0.0, True),
              CentringSample(0.4, -0.03, 0.0, False)]
    with_gaps = [None, None, scored[0], None, scored[1], scored[2], None]
    s = summarize(with_gaps)
    assert s["frames"] == 7 and s["frames_scored"] == 3
    assert s == {**summarize(scored), "frames": 7}
    assert s["time_to_first_centre"] == pytest.approx(0.1) and s["out_of_view"] == pytest.approx(1 / 3)
    with pytest.raises(ValueError, match="no frame with ground truth"):
        summarize([None, None])


def test_overshoot_is_the_step_response_not_later_tracking_error():
    """Only excursions in the window after the first centring count: a moving subject's later
    lag past the centre is tracking error, not overshoot."""
    samples = [
        CentringSample(0.0, 0.2, 0.0, True),
        CentringSample(0.1, 0.04, 0.0, True),  # centred
        CentringSample(0.1 + OVERSHOOT_WINDOW_S / 2, -0.02, 0.0, True),  # 10 % past the centre
        CentringSample(0.1 + OVERSHOOT_WINDOW_S + 0.05, -0.15, 0.0, True),  # later: 75 % past
    ]
    assert summarize(samples)["overshoot"] == pytest.approx(0.1)


def test_never_centred_and_started_centred():
    s = summarize([CentringSample(0.0, 0.3, 0.0, True), CentringSample(0.1, 0.2, 0.0, True)])
    assert s["time_to_first_centre"] is None and s["overshoot"] == 0.0
    s = summarize([CentringSample(0.0, 0.01, 0.0, True), CentringSample(0.1, -0.04, 0.0, True)])
    assert s["time_to_first_centre"] == 0.0 and s["overshoot"] == 0.0
    with pytest.raises(ValueError):
        summarize([])
