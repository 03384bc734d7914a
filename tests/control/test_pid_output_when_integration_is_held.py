"""The output of a step in which conditional integration holds the integral back."""
import pytest

from pipelines.control.pid import Pid


def test_the_output_is_recomputed_from_the_held_integral() -> None:
    """kp * 1.9 = 1.9 plus the step's integral 0.19 would pass the 2.0 limit: the integral is held
    at 0, and the output is what that gives (1.9), not the limit reached with the discarded growth."""
    pid = Pid(kp=1.0, ki=5.0, output_limit=2.0)
    assert pid(1.9, 0.02) == pytest.approx(1.9)
    assert pid.integral == 0.0
