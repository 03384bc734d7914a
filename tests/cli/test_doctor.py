"""``gimbaltrack doctor`` and ``gimbal.diagnostics``: every check passes against the simulator, each
simulator fault turns its own check red with a hint, and the wiggle returns the gimbal and releases."""
from __future__ import annotations

import json
import signal
import subprocess
import threading
import time
from collections.abc import Callable

import can
import pytest

from gimbal.client import GimbalClient
from gimbal.diagnostics import BusCensus, Check, Doctor, RigSettings, wiggle_step
from gimbal.matcher import FIRST_SEQ
from gimbal.messages import Message, message_packet
from gimbal.messages.motion import (
    ANGLES_ATTITUDE,
    SPEED_RELEASE,
    GetAngles,
    SpeedControl,
)
from gimbal.packet import encode_packet
from gimbal.sim import Faults, SimConfig, SimulatedGimbal
from gimbal.sim.slcan_pty import SlcanPty, virtual_pair
from gimbal.transport import packet_frames
from pipelines.cli import main
from tests.support import (
    cli_command,
    free_udp_port,
    signalled,
    subprocess_env,
    wait_until,
)

ALL = ("listen", "version", "latency", "layout", "push", "camera", "integrity", "controller")


DEFAULT_CONFIG, NO_FAULTS, DEFAULT_RIG = SimConfig(), Faults(), RigSettings()


def doctor(config: SimConfig = DEFAULT_CONFIG, faults: Faults = NO_FAULTS, rig: RigSettings = DEFAULT_RIG,
           wiggle: bool = False, channel: str | None = None) -> tuple[dict[str, Check], SimulatedGimbal]:
    """The checks (by name) of a doctor run against a simulated gimbal on a fresh virtual channel."""
    channel = channel or f"doctor-{time.monotonic_ns()}"
    sim = SimulatedGimbal(can.Bus(interface="virtual", channel=channel), config, faults, shutdown_bus=True).start()
    host = can.Bus(interface="virtual", channel=channel)
    census = BusCensus(rig.tx_id, rig.rx_id)
    try:
        with GimbalClient(host, tx_id=rig.tx_id, rx_id=rig.rx_id, listeners=[census],
                          legacy_attitude_order=rig.legacy_order) as client:
            checks = {c.name: c for c in Doctor(client, census, rig).checks(wiggle=wiggle)}
    finally:
        sim.stop()
        host.shutdown()
    return checks, sim


def failed(checks: dict[str, Check]) -> set[str]:
    return {name for name, check in checks.items() if not check.ok}


def doctor_beside(send: Callable[[can.BusABC], None], every: float) -> dict[str, Check]:
    """The checks of a doctor run while another node on its bus calls ``send`` every ``every`` seconds."""
    channel = f"doctor-beside-{time.monotonic_ns()}"
    other = can.Bus(interface="virtual", channel=channel)
    stop = threading.Event()

    def keep_sending() -> None:
        while not stop.wait(every):
            send(other)

    sender = threading.Thread(target=keep_sending)
    sender.start()
    try:
        checks, _ = doctor(channel=channel)
    finally:
        stop.set()
        sender.join()
        other.shutdown()
    return checks


def test_every_check_passes_against_the_simulator() -> None:
    checks, _ = doctor()
    assert tuple(checks) == ALL
    assert failed(checks) == set()
    assert checks["version"].data["version"] == "02.05.00.00"
    assert checks["layout"].data["layout"] == "latest"
    assert checks["latency"].data["answered"] == 50
    assert 40 <= checks["push"].data["hz"] <= 60


def test_legacy_firmware_is_detected_and_passes() -> None:
    checks, _ = doctor(SimConfig(legacy=True))
    assert failed(checks) == set()
    assert checks["layout"].data["layout"] == "legacy"


@pytest.mark.parametrize("config", [SimConfig(push_reply_bit=True), SimConfig(lenient=True)],
                         ids=["push-reply-bit", "lenient"])
def test_other_firmware_variants_pass(config: SimConfig) -> None:
    checks, _ = doctor(config)
    assert failed(checks) == set()


@pytest.mark.parametrize(("bitrate", "passes"), [(1_000_000, True), (500_000, False)])
def test_behind_the_slcan_adapter_only_the_gimbals_bitrate_reaches_it(bitrate: int, passes: bool) -> None:
    """The slcan pseudo-terminal passes frames at 1 Mbit/s only, as a real bus does."""
    pytest.importorskip("serial", reason="python-can's slcan interface needs pyserial")
    adapter_bus, gimbal_bus = virtual_pair()
    with SimulatedGimbal(gimbal_bus, SimConfig(), shutdown_bus=True), SlcanPty(adapter_bus) as pty:
        bus = can.Bus(interface="slcan", channel=pty.path, bitrate=bitrate, sleep_after_open=0)
        rig = RigSettings(bitrate=bitrate)
        census = BusCensus()
        try:
            with GimbalClient(bus, listeners=[census]) as client:
                checks = {c.name: c for c in Doctor(client, census, rig).checks()}
        finally:
            bus.shutdown()
    adapter_bus.shutdown()
    if passes:
        assert failed(checks) == set()
    else:
        assert "version" in failed(checks)
        assert checks["version"].hint.startswith("-b 500000 is not the gimbal's 1000000")


LOSSY = {"push", "camera"}  # lost frames may cost these queries too


@pytest.mark.parametrize(("faults", "config", "red", "also", "hint"), [
    (Faults(drop=0.1, seed=1), SimConfig(), {"latency", "integrity"}, LOSSY, "termination"),
    (Faults(corrupt=0.1, seed=1), SimConfig(), {"latency", "integrity"}, LOSSY, "termination"),
    (Faults(delay_s=0.15), SimConfig(), {"latency"}, set(), "slower than"),
    (Faults(nack=0.3, seed=2), SimConfig(), {"latency", "camera"}, {"push"}, "refuses"),
    (Faults(), SimConfig(camera_connected=False), {"camera"}, set(), "no camera"),
    (Faults(legacy=0.5), SimConfig(), {"layout"}, set(), "another device"),
], ids=["drop", "corrupt", "delay", "nack", "no-camera", "mixed-layout"])
def test_each_fault_turns_its_check_red_with_a_hint(faults: Faults, config: SimConfig, red: set[str],
                                                    also: set[str], hint: str) -> None:
    checks, _ = doctor(config, faults)
    assert red <= failed(checks) <= red | also
    first = next(checks[name] for name in ALL if name in red)
    assert hint in first.hint


def test_a_silent_gimbal_fails_version_and_skips_the_rest_quickly() -> None:
    start = time.monotonic()
    checks, _ = doctor(faults=Faults(silent=(0.0, float("inf"))))
    assert time.monotonic() - start < 5
    assert failed(checks) == set(ALL) - {"listen", "controller"}
    assert "nothing at all on the bus" in checks["version"].hint
    assert checks["latency"].summary.startswith("skipped")


def test_a_wrong_rx_id_names_the_id_the_replies_arrive_on() -> None:
    checks, _ = doctor(rig=RigSettings(rx_id=0x221))
    assert "version" in failed(checks)
    assert "arrive on 0x222, not on --rx-id 0x221" in checks["version"].hint


def test_a_wrong_tx_id_or_bitrate_is_named_in_the_hint() -> None:
    checks, _ = doctor(rig=RigSettings(tx_id=0x224, bitrate=500_000))
    assert "0x224/0x222 are not the document's 0x223/0x222" in checks["version"].hint
    assert "-b 500000 is not the gimbal's 1000000" in checks["version"].hint


def test_foreign_traffic_is_counted_and_passes() -> None:
    checks, _ = doctor(faults=Faults(foreign_rate=200))
    assert failed(checks) == set()
    assert checks["listen"].data["foreign_frames"] > 50
    assert set(checks["listen"].data["foreign_ids"]) <= {"0x426", "0x530", "0x531"}


def test_error_frames_turn_listen_red() -> None:
    census = BusCensus()
    census.on_message_received(can.Message(is_error_frame=True))
    census.on_message_received(can.Message(arbitration_id=0x530, data=b"\x55\x01", is_extended_id=False))
    assert census.counts["error_frames"] == 1 and census.counts["foreign_frames"] == 1

    checks = doctor_beside(lambda noise: noise.send(can.Message(is_error_frame=True)), every=0.05)
    assert not checks["listen"].ok and "bitrate" in checks["listen"].hint


def other_host_run(message: Message) -> dict[str, Check]:
    """A doctor run while another host sends ``message`` on 0x223 five times a second."""
    raw = encode_packet(message_packet(message, FIRST_SEQ + 0x100))

    def other_host(other: can.BusABC) -> None:
        for frame in packet_frames(raw, 0x223):
            other.send(frame)

    return doctor_beside(other_host, every=0.2)


def test_another_controller_on_our_tx_id_is_found() -> None:
    checks = other_host_run(SpeedControl(0, 0, 0, SPEED_RELEASE))
    assert not checks["controller"].ok
    assert checks["controller"].data["commands"]["speed_control"] >= 3
    assert "another host" in checks["controller"].hint


def test_another_hosts_queries_are_reported_but_pass() -> None:
    checks = other_host_run(GetAngles(ANGLES_ATTITUDE))
    assert checks["controller"].ok
    assert checks["controller"].data["commands"]["get_angles"] >= 3
    assert "no control commands" in checks["controller"].summary


def test_the_controller_check_is_the_clients_own_view_of_other_hosts() -> None:
    """#27: the doctor judges another host by the client's ``OtherHosts``, the view on which
    ``track`` refuses to take control, not by a count of its own that could disagree with it."""
    channel = f"doctor-view-{time.monotonic_ns()}"
    sim = SimulatedGimbal(can.Bus(interface="virtual", channel=channel), DEFAULT_CONFIG, shutdown_bus=True).start()
    host = can.Bus(interface="virtual", channel=channel)
    census = BusCensus()
    try:
        with GimbalClient(host, listeners=[census]) as client:
            doctor = Doctor(client, census, DEFAULT_RIG)
            assert doctor.other_controller().ok
            client.other_hosts.on_packet(message_packet(SpeedControl(0, 0, 0, SPEED_RELEASE), FIRST_SEQ), 0.0)
            check = doctor.other_controller()
    finally:
        sim.stop()
        host.shutdown()
    assert not check.ok and check.data["commands"] == {"speed_control": 1} and check.data["control"] == 1


def test_our_own_frames_are_not_another_controller_on_a_loopback_bus() -> None:
    census = BusCensus()
    sent = can.Message(arbitration_id=0x223, data=b"\x55", is_extended_id=False, is_rx=False)
    census.on_message_received(sent)
    assert census.counts["other_host_frames"] == 0 and census.counts["sent_frames"] == 1


def test_wiggle_passes_returns_the_gimbal_and_releases() -> None:
    checks, sim = doctor(SimConfig(initial_joint_deg=(10.0, 0.0, -5.0)), wiggle=True)
    assert failed(checks) == set()
    assert {"yaw follows", "pitch follows", "yaw sign", "pitch sign"} <= set(checks)
    state = sim.state()
    assert state.joint[0] == pytest.approx(10.0, abs=0.2) and state.joint[2] == pytest.approx(-5.0, abs=0.2)
    assert not state.speed_control
    assert state.speeds == (0.0, 0.0, 0.0)


def test_a_flipped_yaw_turns_the_yaw_sign_red_and_the_flag_makes_it_pass() -> None:
    flipped = SimConfig(speed_signs=(-1, 1, 1))
    checks, _ = doctor(flipped, wiggle=True)
    assert failed(checks) == {"yaw sign"}
    assert "toggle --invert-yaw" in checks["yaw sign"].hint
    checks, sim = doctor(flipped, rig=RigSettings(yaw_sign=-1), wiggle=True)
    assert failed(checks) == set()
    assert not sim.state().speed_control


def test_a_reversed_attitude_setting_turns_the_sign_red() -> None:
    checks, _ = doctor(rig=RigSettings(pitch_attitude_sign=-1), wiggle=True)
    assert failed(checks) == {"pitch sign"}


def test_the_legacy_angle_order_is_checked_by_the_wiggle() -> None:
    ypr = SimConfig(legacy=True, legacy_attitude_order="ypr")
    checks, _ = doctor(ypr, wiggle=True)
    assert failed(checks) == {"legacy order"}
    assert "--legacy-order ypr" in checks["legacy order"].hint
    checks, _ = doctor(ypr, rig=RigSettings(legacy_order="ypr"), wiggle=True)
    assert failed(checks) == set()


# -- the command line ------------------------------------------------------------------------

def test_cli_with_the_builtin_simulator(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["doctor", "-i", "sim", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["ok"] is True
    assert [c["name"] for c in result["checks"]] == ["bus", *ALL]


def test_cli_prints_one_line_per_check_and_exits_1_on_a_failure(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["doctor", "-i", "sim", "--tx-id", "0x224", "--rx-id", "0x225"]) == 0  # the sim follows the ids
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("✓ bus:") and out[-1] == "all checks passed"
    assert main(["doctor", "-i", "virtual", "-c", f"doctor-nobody-{time.monotonic_ns()}"]) == 1
    out = capsys.readouterr().out
    assert "✗ version: no answer" in out and "    hint: nothing at all on the bus" in out
    assert out.rstrip().endswith("checks failed")


def test_cli_a_bus_that_cannot_open_is_a_failed_check(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["doctor", "-i", "slcan", "-c", "/dev/nonexistent-adapter", "--json"]) == 1
    result = json.loads(capsys.readouterr().out)
    assert result["ok"] is False and result["checks"][0]["name"] == "bus"
    assert "cannot open the CAN bus" in result["checks"][0]["summary"]


def test_cli_an_unknown_interface_is_bad_input_in_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["doctor", "-i", "nosuchbus", "-c", "x"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.strip().splitlines() == [
        "gimbaltrack doctor: error: cannot open the CAN bus: unknown CAN interface: Unknown interface type \"nosuchbus\""]


def test_cli_against_the_simulator_process_over_udp_multicast() -> None:
    """The issue's 'done when': doctor on udp_multicast against 'gimbaltrack sim' on that group."""
    group, env = "239.74.163.91", subprocess_env(free_udp_port())
    sim = subprocess.Popen(cli_command("sim", "-i", "udp_multicast", "-c", group, "--status-interval", "0.2",
                                       "--foreign-rate", "20"),
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        assert wait_until(lambda: sim.stdout.readline(), 60), "the simulator never started"
        threading.Thread(target=sim.stdout.read, daemon=True).start()  # an unread pipe would stall it
        done = subprocess.run(cli_command("doctor", "-i", "udp_multicast", "-c", group, "--json"),
                              capture_output=True, text=True, env=env, timeout=120, check=False)
    finally:
        sim.terminate()
        sim.wait(30)
    result = json.loads(done.stdout)
    assert done.returncode == 0, result
    assert all(c["ok"] for c in result["checks"])
    assert result["checks"][1]["data"]["foreign_frames"] > 0
    assert result["seconds"] < 10


def test_cli_takes_the_rig_profile_sign_options(tmp_path, capsys: pytest.CaptureFixture[str]) -> None:
    """A profile's [gimbal] invert_yaw reaches the wiggle: the simulator turns the usual way, so it is red."""
    profile = tmp_path / "rig.toml"
    profile.write_text('[bus]\ninterface = "sim"\n[gimbal]\ninvert_yaw = true\n')
    assert main(["doctor", "--profile", str(profile), "--wiggle", "--no-camera", "--json"]) == 1
    result = json.loads(capsys.readouterr().out)
    assert [c["name"] for c in result["checks"] if not c["ok"]] == ["yaw sign"]
    assert "camera" not in [c["name"] for c in result["checks"]]


def test_the_wiggle_steps_away_from_the_end_of_the_documents_range() -> None:
    assert wiggle_step("yaw", 0.0) == 5.0
    assert wiggle_step("yaw", 177.0) == -5.0
    assert wiggle_step("pitch", 144.0) == -5.0
    assert wiggle_step("pitch", -55.0) == 5.0


def test_an_interrupted_wiggle_still_stops_returns_and_releases(monkeypatch: pytest.MonkeyPatch) -> None:
    """Ctrl-C during the speed nudge: the gimbal gets zero speed, control released, and its start."""
    calls = []
    speed = GimbalClient.speed

    def interrupted(self: GimbalClient, *args: object, **kwargs: object) -> None:
        calls.append(args)
        speed(self, *args, **kwargs)
        if len(calls) == 2:
            raise KeyboardInterrupt

    monkeypatch.setattr(GimbalClient, "speed", interrupted)
    channel = f"doctor-interrupted-{time.monotonic_ns()}"
    sim = SimulatedGimbal(can.Bus(interface="virtual", channel=channel), SimConfig(initial_joint_deg=(20.0, 0.0, 0.0)),
                          shutdown_bus=True).start()
    host = can.Bus(interface="virtual", channel=channel)
    census = BusCensus()
    try:
        with pytest.raises(KeyboardInterrupt), GimbalClient(host, listeners=[census]) as client:
            for _ in Doctor(client, census, RigSettings()).checks(wiggle=True):
                pass
        state = sim.state()
    finally:
        sim.stop()
        host.shutdown()
    assert len(calls) == 2
    assert not state.speed_control and state.speeds == (0.0, 0.0, 0.0)
    assert state.joint[0] == pytest.approx(20.0, abs=0.2) and state.joint[2] == pytest.approx(0.0, abs=0.2)


@pytest.mark.parametrize(("signum", "status", "said"), [(signal.SIGINT, 130, "interrupted"),
                                                          (signal.SIGTERM, 143, "terminated (SIGTERM)")])
def test_cli_stopped_by_a_signal_says_so_in_one_line(signum: int, status: int, said: str) -> None:
    code, _, err = signalled(cli_command("doctor", "-i", "sim"), lambda p: p.stdout.readline().startswith("✓ bus"),
                               signum, env=subprocess_env())
    assert code == status
    assert err.strip().splitlines() == [f"gimbaltrack doctor: {said}"]


def test_cli_interrupted_still_prints_the_json_of_what_was_checked(monkeypatch: pytest.MonkeyPatch,
                                                                    capsys: pytest.CaptureFixture[str]) -> None:
    def interrupted(self: Doctor, queries: int = 50) -> Check:
        raise KeyboardInterrupt

    monkeypatch.setattr(Doctor, "latency", interrupted)
    assert main(["doctor", "-i", "sim", "--json"]) == 130
    captured = capsys.readouterr()
    result = json.loads(captured.out)
    assert [c["name"] for c in result["checks"]] == ["bus", "listen", "version", "run"]
    assert result["ok"] is False and result["checks"][-1]["summary"] == "interrupted (SIGINT)"
    assert captured.err.strip() == "gimbaltrack doctor: interrupted"
