"""Re-enabling the parameter push (0x07) restarts its schedule: one push at once, then one a period."""
from __future__ import annotations

from gimbal.messages import telemetry
from gimbal.messages.telemetry import PUSH_DISABLE, PUSH_ENABLE, PushControl
from gimbal.sim import SimConfig
from gimbal.sim.model import GimbalModel


def push_times(model: GimbalModel, start: float, end: float, step: float = 0.001) -> list[float]:
    """Times (to ``step``) at which ``advance`` returned a parameter push."""
    times, now = [], start
    while now <= end + 1e-9:
        if any(isinstance(m, telemetry.ParameterPush) for m in model.advance(now)):
            times.append(round(now, 3))
        now += step
    return times


def test_a_push_re_enabled_long_after_it_was_disabled_keeps_the_configured_period() -> None:
    """No catch-up burst: after 4 s off, the pushes are again 20 ms apart (50 Hz), the first at once."""
    model = GimbalModel(SimConfig(push_rate_hz=50.0), 0.0)
    assert model.handle(PushControl(PUSH_ENABLE), 0.0).ok
    push_times(model, 0.0, 1.0)
    assert model.handle(PushControl(PUSH_DISABLE), 1.0).ok
    assert push_times(model, 1.0, 5.0, step=0.01) == []
    assert model.handle(PushControl(PUSH_ENABLE), 5.0).ok
    times = push_times(model, 5.0, 5.1)
    assert times[0] == 5.0
    gaps = [round(b - a, 3) for a, b in zip(times, times[1:])]
    assert gaps and all(abs(g - 0.02) <= 0.0015 for g in gaps), gaps


def test_a_late_advance_sends_one_catch_up_push_not_a_burst() -> None:
    """The tick thread woken 200 ms late at 50 Hz: at most one extra push, then 20 ms apart again."""
    model = GimbalModel(SimConfig(push_rate_hz=50.0), 0.0)
    assert model.handle(PushControl(PUSH_ENABLE), 0.0).ok
    assert push_times(model, 0.0, 0.0) == [0.0]
    times = push_times(model, 0.2, 0.26)
    assert times[0] == 0.2 and len(times) <= 5, times
    assert all(b - a >= 0.019 for a, b in zip(times[2:], times[3:])), times
