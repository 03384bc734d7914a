"""The simulated gimbal behind a SLCAN adapter on a pseudo-terminal, driven through python-can's
``slcan`` interface: in process, and end to end (``gimbaltrack sim --slcan-pty`` in one process,
``gimbal`` and ``track`` with ``-i slcan -c PTY`` in others)."""
from __future__ import annotations

import json
import os
import subprocess
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import can
import pytest

from gimbal.client import GimbalClient
from gimbal.errors import GimbalTimeoutError
from gimbal.sim import SimConfig, SimulatedGimbal
from gimbal.sim.slcan_pty import ERROR, OK, SlcanPty, virtual_pair
from tests.support import ROOT, cli_command, subprocess_env, wait_until

pytest.importorskip("serial", reason="python-can's slcan interface needs pyserial")


@pytest.fixture
def adapter() -> Iterator[tuple[SlcanPty, SimulatedGimbal]]:
    adapter_bus, gimbal_bus = virtual_pair()
    with SimulatedGimbal(gimbal_bus, SimConfig(), shutdown_bus=True) as sim, SlcanPty(adapter_bus) as pty:
        yield pty, sim
    adapter_bus.shutdown()


def slcan_bus(path: str, bitrate: int = 1_000_000) -> can.BusABC:
    return can.Bus(interface="slcan", channel=path, bitrate=bitrate, sleep_after_open=0)


def test_commands_are_answered_as_a_lawicel_adapter_answers(adapter) -> None:
    pty, _ = adapter
    assert pty.command("O") == ERROR  # no bitrate yet
    assert pty.command("t2231AA") == ERROR  # channel closed
    assert pty.command("S8") == OK and pty.bitrate == 1_000_000
    assert pty.command("O") == OK and pty.passes_frames
    assert pty.command("S6") == ERROR  # not while open
    assert pty.command("V") == b"V1013\r"
    assert pty.command("t2232AA") == ERROR  # two data bytes announced, one given
    assert pty.command("t8001AA") == ERROR  # not an 11-bit id
    assert pty.command("t2231AA") == b"z\r"
    assert pty.command("X") == ERROR
    assert pty.command("C") == OK and not pty.passes_frames


def test_python_can_slcan_reaches_the_gimbal_and_the_half_second_stop_holds(adapter) -> None:
    pty, sim = adapter
    bus = slcan_bus(pty.path)
    try:
        assert bus.get_version(1.0) == (10, 13)  # before the client's receive thread reads the port
        with GimbalClient(bus) as client:
            client.position(10.0, 0.0, -5.0, time_s=0.2)
            assert wait_until(lambda: sim.state().joint == (10.0, 0.0, -5.0), 2.0)
            assert client.get_angles("joint").yaw == 10.0
            client.speed(20.0, 0.0)  # one command, never repeated
            sent = time.monotonic()
            assert wait_until(lambda: sim.state().speeds[0] != 0.0, 0.3, step=0.002)
            assert wait_until(lambda: sim.state().speeds == (0.0, 0.0, 0.0), 1.0, step=0.002)
            stopped_after = time.monotonic() - sent
            assert 0.5 <= stopped_after <= 0.65, stopped_after
    finally:
        bus.shutdown()
    assert pty.stats["to_bus"] > 0 and pty.stats["to_serial"] > 0


def test_an_adapter_at_another_bitrate_reaches_nothing(adapter) -> None:
    pty, sim = adapter
    bus = slcan_bus(pty.path, bitrate=500_000)
    try:
        with GimbalClient(bus, timeout=0.1, retries=0) as client, pytest.raises(GimbalTimeoutError):
            client.get_angles()
    finally:
        bus.shutdown()
    assert sum(sim.state().commands.values()) == 0


def test_gimbal_and_track_over_slcan_against_the_sim_process(tmp_path: Path) -> None:
    env = subprocess_env()
    sim = subprocess.Popen(cli_command("sim", "--slcan-pty", "--status-interval", "0.2", "--json"),
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT, env=env)
    try:
        path = sim.stdout.readline().strip()
        assert path.startswith("/dev/") and os.path.exists(path), path
        lines: list[str] = []  # read as they come: a full pipe would hold the status line back
        reader = threading.Thread(target=lambda: lines.extend(sim.stdout), daemon=True)
        reader.start()
        bus = ["-i", "slcan", "-c", path]
        angles = subprocess.run(cli_command("gimbal", *bus, "--json", "angles"), capture_output=True, text=True,
                                timeout=60, cwd=ROOT, env=env)
        assert angles.returncode == 0, angles.stderr
        assert json.loads(angles.stdout)["joint"] == {"yaw": 0.0, "roll": 0.0, "pitch": 0.0}
        out = tmp_path / "track"
        track = subprocess.run(cli_command("track", "samples/demo.mp4", "--roi", "138,152,64,96", "--max-frames",
                                           "90", "--no-video", "--quiet", "--out", str(out), *bus),
                               capture_output=True, text=True, timeout=120, cwd=ROOT, env=env)
        assert track.returncode == 0, track.stderr
        assert "Traceback" not in track.stderr
        sent = [line for line in (out / "can.log").read_text().splitlines() if " 223#" in line]
        assert len(sent) > 10  # speed commands went out through the adapter
        time.sleep(0.8)  # beyond the 0.5 s of the last command, whatever track sent last
    finally:
        sim.terminate()
        sim.wait(timeout=10)
    reader.join(timeout=5)
    assert sim.returncode == 0, sim.stderr.read()
    last = json.loads(lines[-1])  # a status line from the last 0.2 s
    assert last["speeds"] == [0.0, 0.0, 0.0] and not last["speed_control"]
    assert last["commands"].get("speed_control", 0) > 10, last


@pytest.mark.parametrize("extra", [["-c", "/dev/ttyACM0"], ["-b", "500000"], ["-i", "virtual"]])
def test_slcan_pty_refuses_bus_options_in_one_line(extra: list[str]) -> None:
    done = subprocess.run(cli_command("sim", "--slcan-pty", *extra, "--duration", "2"), capture_output=True,
                          text=True, timeout=60, cwd=ROOT, env=subprocess_env())
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.strip().splitlines() == [
        "gimbaltrack sim: error: --slcan-pty is the bus: it takes no -i/--interface, -c/--channel or -b/--bitrate"]
