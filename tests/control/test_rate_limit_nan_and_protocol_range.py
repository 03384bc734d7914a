"""``limit_rate`` on a missing setpoint and on limits beyond the protocol's speed range."""
import math

import pytest

from pipelines.control.limits import PROTOCOL_MAX_SPEED_DPS, limit_rate


def test_a_nan_setpoint_counts_as_exactly_zero() -> None:
    assert limit_rate(0.5, math.nan, 100.0, 100.0, 0.1) == 0.0
    assert limit_rate(-3.0, math.nan, 100.0, 100.0, 0.1) == 0.0
    assert limit_rate(0.0, math.nan, 100.0, 100.0, 0.1) == 0.0


@pytest.mark.parametrize("wanted", [1000.0, -1000.0])
def test_the_protocol_range_caps_a_larger_speed_limit(wanted: float) -> None:
    """The DJI R SDK speed command stops at 360 deg/s whatever limit a caller passes."""
    assert PROTOCOL_MAX_SPEED_DPS == 360.0
    assert limit_rate(0.0, wanted, 500.0, math.inf, 1.0) == math.copysign(360.0, wanted)


def test_the_speed_range_holds_even_when_the_previous_setpoint_was_outside_it() -> None:
    """A setpoint is never outside +-max_speed, even when that takes a step beyond ``max_accel * dt``
    (a previous setpoint sent under a higher limit)."""
    assert limit_rate(200.0, 200.0, 120.0, 600.0, 0.02) == 120.0
    assert limit_rate(-400.0, -50.0, 500.0, 600.0, 0.02) == -360.0
