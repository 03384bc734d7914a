"""Issue #26 item 3: two `track` processes on one gimbal both ran, its yaw speed flipping between
their setpoints, with no word without -v. A newcomer now listens first and refuses (exit 4)."""
from __future__ import annotations

import json
import uuid
from collections.abc import Iterator
from pathlib import Path

import can
import pytest

from gimbal.client import GimbalClient
from gimbal.sim import SimConfig, SimulatedGimbal
from gimbal.transport import HOST_TX_ID
from pipelines.cli.track_cmd import EXIT_DEGRADED_LINK, EXIT_OTHER_CONTROLLER
from pipelines.outputs.telemetry import read_telemetry
from tests.track.helpers import DEMO, DEMO_ROI, run_track


@pytest.fixture
def driven_gimbal() -> Iterator[tuple[str, SimulatedGimbal]]:
    """A simulated gimbal on a virtual channel, driven at 5 °/s yaw by another host."""
    channel = f"gimbaltrack-two-{uuid.uuid4().hex}"
    sim_bus = can.Bus(interface="virtual", channel=channel)
    with SimulatedGimbal(sim_bus, SimConfig(), shutdown_bus=True) as sim, \
            GimbalClient(interface="virtual", channel=channel) as other:
        streamer = other.speed_streamer(max_age=60.0)
        streamer.set(5.0, 0.0)
        yield channel, sim


def test_a_newcomer_refuses_to_take_over_a_gimbal_another_host_drives(
        tmp_path: Path, driven_gimbal: tuple[str, SimulatedGimbal], capsys: pytest.CaptureFixture[str]) -> None:
    channel, sim = driven_gimbal
    out = tmp_path / "out"
    code = run_track(DEMO, out, "--roi", DEMO_ROI, "--max-frames", "10", "-i", "virtual", "-c", channel)
    err = capsys.readouterr().err.strip()
    assert code == EXIT_OTHER_CONTROLLER
    assert len(err.splitlines()) == 1 and "another host is driving the gimbal" in err
    assert "speed_control" in err and "--shared-bus" in err
    sent = [f for f in can.LogReader(str(out / "can.log")) if not f.is_rx]
    assert sent == []  # nothing taken over, not even a push setting
    state = sim.state()
    assert state.speed_control and state.speeds[0] == pytest.approx(5.0)
    assert [f for f in can.LogReader(str(out / "can.log")) if f.arbitration_id == HOST_TX_ID]  # what it saw is logged


def test_with_shared_bus_it_runs_and_says_once_that_another_host_drives(
        tmp_path: Path, driven_gimbal: tuple[str, SimulatedGimbal], capsys: pytest.CaptureFixture[str]) -> None:
    channel, _ = driven_gimbal
    out = tmp_path / "out"
    code = run_track(DEMO, out, "--roi", DEMO_ROI, "--max-frames", "30", "--no-video", "-i", "virtual",
                     "-c", channel, "--shared-bus")
    captured = capsys.readouterr()
    assert code == EXIT_DEGRADED_LINK
    said = [line for line in captured.err.splitlines() if "another host is driving this gimbal too" in line]
    assert len(said) == 1 and "speed_control" in said[0]
    assert "another host sent" in captured.out
    telemetry = read_telemetry(out / "telemetry.jsonl")
    assert len(telemetry) == 30 and telemetry[-1]["other_hosts"] > 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["bus_health"]["other_hosts"]["control"] > 0
