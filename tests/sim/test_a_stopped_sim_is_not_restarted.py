"""A stopped simulated gimbal says it cannot be started again (it said "already started")."""
from __future__ import annotations

import pytest

from gimbal.sim import start_in_process


def test_start_after_stop_names_the_stop() -> None:
    host_bus, sim = start_in_process()
    try:
        with pytest.raises(RuntimeError, match="already started"):
            sim.start()
        sim.stop()
        with pytest.raises(RuntimeError, match="stopped simulated gimbal cannot be started again"):
            sim.start()
    finally:
        sim.stop()
        host_bus.shutdown()
