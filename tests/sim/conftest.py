"""Fixtures: an in-process simulated gimbal with a raw host on the other end of the bus."""
from __future__ import annotations

from collections.abc import Iterator

import can
import pytest

from gimbal.sim import Faults, SimConfig, SimulatedGimbal, start_in_process
from tests.sim.helpers import RawHost


@pytest.fixture
def make_sim() -> Iterator:  # type: ignore[type-arg]
    """Factory: ``make_sim(config=None, faults=None) -> (RawHost, SimulatedGimbal, host_bus)``."""
    started: list[tuple[can.BusABC, SimulatedGimbal]] = []

    def make(config: SimConfig | None = None, faults: Faults | None = None):  # type: ignore[no-untyped-def]
        bus, sim = start_in_process(config, faults)
        started.append((bus, sim))
        return RawHost(bus), sim, bus

    yield make
    for bus, sim in started:
        sim.stop()
        bus.shutdown()


@pytest.fixture
def sim_host(make_sim):  # type: ignore[no-untyped-def]
    host, sim, _ = make_sim()
    return host, sim
