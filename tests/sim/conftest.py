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


@pytest.fixture
def make_client(make_sim):  # type: ignore[no-untyped-def]
    """Factory: ``make_client(config=None, faults=None, **client_kwargs) -> (GimbalClient, sim)``;
    clients are closed (safety stop) before their simulators stop."""
    from gimbal.client import GimbalClient
    clients: list[GimbalClient] = []

    def make(config: SimConfig | None = None, faults: Faults | None = None, **kwargs):  # type: ignore[no-untyped-def]
        _, sim, bus = make_sim(config, faults)
        client = GimbalClient(bus, **kwargs)
        clients.append(client)
        return client, sim

    yield make
    for client in clients:
        client.close()
