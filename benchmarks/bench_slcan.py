"""Request/reply time and the 0.5 s stop through python-can's slcan interface and the simulated
SLCAN adapter on a pseudo-terminal, against the in-process virtual bus in the same run.

Run: .venv/bin/python benchmarks/bench_slcan.py [--requests 200]
"""
from __future__ import annotations

import argparse
import statistics
import time

import can

from gimbal.client import GimbalClient
from gimbal.sim import SimConfig, SimulatedGimbal, start_in_process
from gimbal.sim.slcan_pty import SlcanPty, virtual_pair
from machine import describe_machine


def round_trips(client: GimbalClient, count: int) -> list[float]:
    times = []
    for _ in range(count):
        start = time.perf_counter()
        client.get_angles()
        times.append(time.perf_counter() - start)
    return times


def stop_time(client: GimbalClient, sim: SimulatedGimbal) -> float:
    """Seconds from one speed command until the simulated gimbal is at rest."""
    client.speed(20.0, 0.0)
    sent = time.monotonic()
    while sim.state().speeds[0] == 0.0 and time.monotonic() - sent < 0.3:
        time.sleep(0.001)
    while sim.state().speeds != (0.0, 0.0, 0.0):
        time.sleep(0.001)
    return time.monotonic() - sent


def measure(client: GimbalClient, sim: SimulatedGimbal, count: int) -> tuple[float, float, float]:
    times = round_trips(client, count)
    return statistics.median(times), sorted(times)[int(0.95 * (len(times) - 1))], stop_time(client, sim)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--requests", type=int, default=200)
    args = parser.parse_args()
    print(describe_machine())
    host_bus, sim = start_in_process(SimConfig())
    with GimbalClient(host_bus, timeout=0.5) as client:
        virtual = measure(client, sim, args.requests)
    sim.stop()
    host_bus.shutdown()
    adapter_bus, gimbal_bus = virtual_pair()
    with SimulatedGimbal(gimbal_bus, SimConfig(), shutdown_bus=True) as sim, SlcanPty(adapter_bus) as pty:
        bus = can.Bus(interface="slcan", channel=pty.path, bitrate=1_000_000, sleep_after_open=0)
        with GimbalClient(bus, timeout=0.5) as client:
            slcan = measure(client, sim, args.requests)
        bus.shutdown()
    adapter_bus.shutdown()
    for name, (median, p95, stop) in (("virtual", virtual), ("slcan pty", slcan)):
        print(f"{name:10s} get_angles median {median * 1000:.2f} ms, p95 {p95 * 1000:.2f} ms; "
              f"one speed command at rest after {stop:.3f} s")
    print(f"slcan / virtual median: {slcan[0] / virtual[0]:.1f}x")


if __name__ == "__main__":
    main()
