"""Live settings by their short names."""
import pytest

from pipelines.control.controller import ControlConfig
from pipelines.control.tuning import retuned, settings_of


def test_short_names_reach_their_fields() -> None:
    config = retuned(ControlConfig(), {"dead_zone": 0.3, "kp": 5.0, "ki": 0.1, "kd": 0.2})
    assert settings_of(config) == {"max_speed": 120.0, "dead_zone": 0.3, "kp": 5.0, "ki": 0.1, "kd": 0.2}


def test_a_higher_speed_limit_raises_the_acceleration_limit_as_far_as_the_stop_ramp_needs() -> None:
    base = ControlConfig()
    assert retuned(base, {"max_speed": 60.0}).max_accel_dps2 == base.max_accel_dps2
    faster = retuned(base, {"max_speed": 300.0})
    assert faster.max_accel_dps2 == pytest.approx(300.0 / base.ramp_s) and faster.max_speed_dps == 300.0


def test_a_value_the_config_refuses_is_a_value_error() -> None:
    with pytest.raises(ValueError, match="max_speed_dps"):
        retuned(ControlConfig(), {"max_speed": 500.0})
