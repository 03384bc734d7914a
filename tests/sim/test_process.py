"""The simulator as its own process (``gimbaltrack sim``) on udp_multicast, driven from this one."""
from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import threading
import time
from collections.abc import Iterator

import pytest

from gimbal.client import GimbalClient
from gimbal.errors import GimbalError, ReturnCodeError
from gimbal.messages.telemetry import ParameterPush
from pipelines.cli import main
from tests.support import ROOT, cli_command, free_udp_port, subprocess_env

# Non-default ids, and a port of its own, keep this test apart from anything else using udp_multicast.
IDS = ["--tx-id", "0x323", "--rx-id", "0x322"]
PORT = free_udp_port()
ENV = subprocess_env(PORT)


def group() -> str:
    return f"239.74.{random.randrange(1, 255)}.{random.randrange(1, 255)}"


@pytest.fixture
def sim_process() -> Iterator[tuple[subprocess.Popen[str], str]]:
    channel = group()
    proc = subprocess.Popen(cli_command("sim", "-i", "udp_multicast", "-c", channel, *IDS,
                                        "--status-interval", "0.2", "--push-rate", "40", "--version", "01.02.0A.0B"),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT, env=ENV)
    yield proc, channel
    if proc.poll() is None:
        proc.kill()
        proc.communicate()


#: How long the simulator process may take to answer: a Python process importing OpenCV can take
#: several seconds on a loaded machine, and a slow start is not a defect.
START_DEADLINE_S = 30.0


def connect(channel: str) -> GimbalClient:
    client = GimbalClient(interface="udp_multicast", channel=channel, port=PORT, tx_id=0x323, rx_id=0x322,
                          timeout=0.3)
    deadline = time.monotonic() + START_DEADLINE_S
    while True:
        try:
            client.get_angles()
            return client
        except GimbalError:
            if time.monotonic() > deadline:
                client.close()
                raise


def test_two_processes_over_udp_multicast(sim_process) -> None:
    proc, channel = sim_process
    with connect(channel) as client:
        assert client.version().version_text == "01.02.0A.0B"
        client.position(20.0, 0.0, -10.0, time_s=0.3)
        time.sleep(0.45)
        joint = client.get_angles("joint")
        assert (joint.yaw, joint.roll, joint.pitch) == (20.0, 0.0, -10.0)
        client.start_recording()
        assert client.camera_status() is True
        arrivals: list[float] = []
        client.on_push(ParameterPush, lambda m, t: arrivals.append(t))
        client.set_push(True)
        time.sleep(0.6)
        client.set_push(False)
        assert 0.85 * 40 * 0.5 <= len(arrivals) <= 1.15 * 40 * 0.6 + 1
        with pytest.raises(ReturnCodeError):
            client.position(170.0, 0.0, 145.5)  # pitch beyond the +145° user limit: refused
        streamer = client.speed_streamer(rate_hz=25.0)
        streamer.set(30.0, 0.0)
        time.sleep(0.3)
    time.sleep(0.3)  # leaving the client stopped the gimbal: the angle no longer changes
    with connect(channel) as client:
        first = client.get_angles("joint").yaw
        time.sleep(0.2)
        assert client.get_angles("joint").yaw == first
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=5)
    assert proc.returncode == 0, err
    lines = out.strip().splitlines()
    assert len(lines) >= 3 and lines[-1].startswith("t=") and "rec=on" in lines[-1]


def test_gimbal_cli_drives_the_simulator_process(sim_process) -> None:
    proc, channel = sim_process
    bus = ["-i", "udp_multicast", "-c", channel, *IDS, "--timeout", "0.3"]

    def gimbal(*args: str) -> None:
        done = subprocess.run(cli_command("gimbal", *args, *bus), capture_output=True, text=True, timeout=30,
                              env=ENV)
        assert done.returncode == 0, done.stderr

    with connect(channel) as client:
        gimbal("move", "--yaw", "15", "--pitch", "-5", "--time", "0.2")
        gimbal("record", "start")
        time.sleep(0.3)
        joint = client.get_angles("joint")
        assert (joint.yaw, joint.pitch) == (15.0, -5.0) and client.camera_status() is True


def test_duration_status_lines_and_json(capsys) -> None:
    assert main(["sim", "-i", "virtual", "-c", f"sim-cli-{os.getpid()}", "--duration", "0.35",
                 "--status-interval", "0.1", "--json"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert 2 <= len(lines) <= 4
    assert json.loads(lines[-1])["motors_on"] is True


FOREIGN_RATE = "--foreign-rate takes a rate from 0 to 20000 Hz (a 1 Mbit/s bus carries less)"
PUSH_RATE = "--push-rate takes a rate above 0 Hz, at most 1000 Hz (a push takes several frames of a 1 Mbit/s bus)"


@pytest.mark.parametrize("args, message", [
    (["--drop", "1.5"], "--drop takes a fraction from 0 to 1, not 1.5"),
    (["--push-rate", "0"], f"{PUSH_RATE}, not 0"),
    (["--push-rate", "1e300", "--duration", "0.2"], f"{PUSH_RATE}, not 1e+300"),  # once flooded the bus
    # NaN once passed every check and stopped the simulator's threads; the words were SimConfig's
    (["--delay-ms", "nan"], "--delay-ms takes a finite delay, 0 or more, not nan"),
    (["--delay-ms=-5"], "--delay-ms takes a finite delay, 0 or more, not -5"),  # the option's unit, not Faults'
    (["--accel", "inf"], "--accel takes a finite acceleration above 0, not inf"),
    (["--base-yaw", "nan"], "--base-yaw takes a finite angle, not nan"),
    (["--foreign-rate", "nan"], f"{FOREIGN_RATE}, not nan"),
    (["--foreign-rate", "1e300"], f"{FOREIGN_RATE}, not 1e+300"),  # once let through: that many frames a tick
    (["--push-rate", "inf"], f"{PUSH_RATE}, not inf"),
    (["--calibration-time", "-1"], "--calibration-time takes a finite time, 0 s or more, not -1"),
    (["--status-interval", "nan"], "--status-interval takes a finite interval, 0 s or more, not nan"),
    (["--nack-code", "999"], "--nack-code takes a return code, 1 to 0xFF (0 means executed), not 999"),
    (["--nack-code", "0"], "--nack-code takes a return code, 1 to 0xFF (0 means executed), not 0"),
    # the range checks are SimConfig's and Faults', in the options' words
    (["--silent", "3:1"], "--silent takes a window START:END in seconds, 0 <= START <= END (END may be inf), not 3:1"),
    (["--silent", "inf:inf", "--duration", "0.2"], "--silent takes a window START:END"),
    (["--version", "0x100000000"], "--version takes a 32-bit version, 0 to 0xFFFFFFFF, not 4294967296"),
    (["--duration", "0"], "--duration must be positive"),
    (["--tx-id", "0x222"], "must differ"),
    (["-i", "sim"], "in-process simulator"),
    (["-i", "no_such_interface"], "cannot open the CAN bus"),
])
def test_bad_input_is_a_one_line_error(capsys, args: list[str], message: str) -> None:
    assert main(["sim", "--duration", "2", *args]) == 2  # an option taken by mistake ends the run, not hangs it
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1


@pytest.mark.parametrize("args", [["--silent", "3"], ["--version", "1.2.3"], ["--fault-direction", "up"],
                                  ["--duration", "-1"], ["--duration", "nan"]])  # nan once ran for ever
def test_malformed_options_are_usage_errors(capsys, args: list[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["sim", *args])
    assert exc.value.code == 2


def test_a_status_interval_beyond_what_a_thread_can_wait_runs_until_stopped(capsys) -> None:
    """``--status-interval 1e300`` passes the finite-number check; waiting for that status line
    was an OverflowError traceback at once."""
    threading.Timer(1.0, os.kill, (os.getpid(), signal.SIGTERM)).start()  # to the process, as `kill` does
    assert main(["sim", "-i", "virtual", "-c", f"sim-cli-{os.getpid()}", "--status-interval", "1e300"]) == 0
