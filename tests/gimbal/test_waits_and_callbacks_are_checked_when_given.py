"""Timeouts, retry counts and push callbacks are checked where they are given, by name: a
``retries=1.5``, a numpy timeout, a per-request NaN or negative timeout, a push wait of ``None``
and a callback of ``None`` were taken and failed later (a TypeError on the first request, retries
"within nan ms", a traceback logged on the receive thread for every push)."""
from __future__ import annotations

import math
from collections.abc import Iterator

import can
import numpy as np
import pytest

from gimbal.client import GimbalClient
from gimbal.messages.motion import GetAngles
from gimbal.messages.telemetry import ParameterPush
from gimbal.sim import start_in_process


@pytest.fixture
def bus(channel: str) -> Iterator[can.BusABC]:
    bus = can.Bus(interface="virtual", channel=channel)
    yield bus
    bus.shutdown()


@pytest.mark.parametrize("retries", [1.5, -1, True, None, "2"])
def test_a_retry_count_that_is_no_whole_number_is_refused(bus: can.BusABC, retries: object) -> None:
    with pytest.raises(ValueError, match="retries must be a whole number, 0 or more, not"):
        GimbalClient(bus, retries=retries)  # type: ignore[arg-type]


@pytest.mark.parametrize("timeout", [None, "0.1", True])
def test_a_timeout_that_is_no_number_is_refused(bus: can.BusABC, timeout: object) -> None:
    with pytest.raises(ValueError, match="timeout must be above 0"):
        GimbalClient(bus, timeout=timeout)  # type: ignore[arg-type]


def test_numpy_numbers_are_taken() -> None:
    host_bus, sim = start_in_process()
    try:
        with GimbalClient(host_bus, timeout=np.float32(0.2), retries=np.int64(1)) as client:
            assert (client.timeout, client.retries) == (pytest.approx(0.2), 1)
            assert client.get_angles().kind == "attitude"
    finally:
        sim.stop()
        host_bus.shutdown()


@pytest.mark.parametrize("timeout", [math.nan, -1.0, 0.0])
def test_a_per_request_timeout_is_checked(bus: can.BusABC, timeout: float) -> None:
    with GimbalClient(bus) as client:
        with pytest.raises(ValueError, match="timeout must be above 0"):
            client.request(GetAngles(1), timeout=timeout)


@pytest.mark.parametrize("timeout", [None, math.nan, -1.0])
def test_a_push_wait_timeout_is_checked(bus: can.BusABC, timeout: object) -> None:
    with GimbalClient(bus) as client:
        with pytest.raises(ValueError, match="a push timeout must be 0 to"):
            client.wait_for_push(ParameterPush, timeout)  # type: ignore[arg-type]


def test_a_callback_that_cannot_be_called_is_refused(bus: can.BusABC) -> None:
    with GimbalClient(bus) as client:
        with pytest.raises(TypeError, match="a push callback must be callable, not None"):
            client.on_push(ParameterPush, None)  # type: ignore[arg-type]
