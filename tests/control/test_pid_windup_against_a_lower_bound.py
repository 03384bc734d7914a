"""Conditional integration when a later limiter holds the output above what the PID wants."""
import pytest

from pipelines.control.pid import Pid


def test_no_windup_while_held_at_a_positive_lower_bound() -> None:
    """Slowing from a high speed, the acceleration limit keeps the command within (5, 8): the PID
    wants a little less than zero (error -1), and its integral must not grow negative meanwhile."""
    pid = Pid(kp=1.0, ki=2.0, output_limit=100.0)
    for _ in range(50):
        out = pid(-1.0, 0.02, bounds=(5.0, 8.0))
    assert out == 5.0 and pid.integral == 0.0
    assert pid(1.0, 0.02) == pytest.approx(1.0 + 2.0 * 0.02)  # nothing wound up to unwind
