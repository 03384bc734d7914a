import math

import pytest

from pipelines.control.pid import Pid


DT = 0.02


def test_proportional_and_integral_with_fixed_dt():
    pid = Pid(2.0, ki=1.0)
    assert pid(1.0, DT) == pytest.approx(2.0 + 1.0 * DT)
    assert pid(1.0, DT) == pytest.approx(2.0 + 2.0 * DT)


def test_integral_is_clamped():
    pid = Pid(0.0, ki=10.0, integral_limit=0.5)
    for _ in range(1000):
        out = pid(1.0, DT)
    assert out == pytest.approx(0.5)
    assert pid.integral == pytest.approx(0.5)


def test_no_windup_while_saturated():
    pid = Pid(1.0, ki=1.0, output_limit=2.0)
    for _ in range(500):  # 10 s of a large error: the output sits at the limit
        assert pid(5.0, DT) <= 2.0
    wound = pid.integral
    assert wound < 2.0
    # the error reverses: the output leaves saturation at once instead of after unwinding
    assert pid(-0.5, DT) < 2.0
    assert pid(-0.5, DT) < 1.5


def test_output_clamp_and_slew():
    pid = Pid(100.0, output_limit=10.0, slew_rate=50.0)
    assert pid(1.0, DT) == pytest.approx(1.0)  # 50/s * 0.02 s
    for _ in range(50):
        out = pid(1.0, DT)
    assert out == pytest.approx(10.0)
    assert pid(-1.0, DT) == pytest.approx(9.0)


def test_derivative_on_measurement_has_no_setpoint_kick():
    on_meas, on_err = Pid(0.0, kd=1.0), Pid(0.0, kd=1.0)
    on_meas(0.0, DT, measurement=0.0)
    on_err(0.0, DT)
    # the setpoint jumps by 10 while the measurement stays put
    assert on_meas(10.0, DT, measurement=0.0) == 0.0
    assert on_err(10.0, DT) == pytest.approx(10.0 / DT)
    # the measurement moving towards the setpoint is damped
    assert on_meas(9.0, DT, measurement=1.0) == pytest.approx(-1.0 / DT)


def test_deadband_is_continuous():
    pid = Pid(1.0, deadband=0.5)
    assert pid(0.4, DT) == 0.0
    assert pid(-0.5, DT) == 0.0
    assert pid(0.6, DT) == pytest.approx(0.1)
    assert pid(-2.0, DT) == pytest.approx(-1.5)


def test_reset_and_bad_arguments():
    pid = Pid(1.0, ki=1.0)
    pid(3.0, DT)
    pid.reset()
    assert pid.integral == 0.0 and pid.output == 0.0
    with pytest.raises(ValueError):
        pid(1.0, 0.0)
    with pytest.raises(ValueError):
        Pid(1.0, output_limit=0.0)
    assert math.isinf(Pid(1.0).output_limit)


def test_nan_is_refused_not_clamped_to_the_limit():
    from pipelines.control.limits import limit_rate
    from pipelines.control.pid import clamp

    with pytest.raises(ValueError):
        clamp(float("nan"), 10.0)
    with pytest.raises(ValueError):
        Pid(1.0, 1.0, output_limit=10.0)(float("nan"), 0.1)
    assert limit_rate(20.0, float("nan"), 100.0, 100.0, 0.1) == pytest.approx(10.0)  # towards 0


def test_no_windup_against_bounds_a_later_limiter_sets():
    """The controller's acceleration limit sits after the PID: the integral once grew while it held
    the command back (0.9-1.8 deg/s left after a step or a stall, a slowly decaying offset)."""
    pid = Pid(kp=1.0, ki=2.0, output_limit=100.0)
    for _ in range(50):
        out = pid(10.0, 0.02, bounds=(-5.0, 5.0))
    assert out == 5.0 and pid.integral == 0.0
    free = Pid(kp=1.0, ki=2.0, output_limit=100.0)
    for _ in range(50):
        free(10.0, 0.02)
    assert free.integral == pytest.approx(20.0)


def test_a_call_that_does_not_integrate_leaves_the_integral_alone():
    pid = Pid(1.0, ki=2.0)
    pid(1.0, 0.5)
    assert pid(3.0, 0.5, integrate=False) == pytest.approx(3.0 + 1.0)
    assert pid.integral == pytest.approx(1.0)


# The output of a step in which conditional integration holds the integral back.
def test_the_output_is_recomputed_from_the_held_integral() -> None:
    """kp * 1.9 = 1.9 plus the step's integral 0.19 would pass the 2.0 limit: the integral is held
    at 0, and the output is what that gives (1.9), not the limit reached with the discarded growth."""
    pid = Pid(kp=1.0, ki=5.0, output_limit=2.0)
    assert pid(1.9, 0.02) == pytest.approx(1.9)
    assert pid.integral == 0.0


# Conditional integration when a later limiter holds the output above what the PID wants.
def test_no_windup_while_held_at_a_positive_lower_bound() -> None:
    """Slowing from a high speed, the acceleration limit keeps the command within (5, 8): the PID
    wants a little less than zero (error -1), and its integral must not grow negative meanwhile."""
    pid = Pid(kp=1.0, ki=2.0, output_limit=100.0)
    for _ in range(50):
        out = pid(-1.0, 0.02, bounds=(5.0, 8.0))
    assert out == 5.0 and pid.integral == 0.0
    assert pid(1.0, 0.02) == pytest.approx(1.0 + 2.0 * 0.02)  # nothing wound up to unwind
