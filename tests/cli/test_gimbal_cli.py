"""``gimbaltrack gimbal ...`` through ``pipelines.cli.main`` against a scripted peer on the
virtual bus (and the built-in simulator when it is present)."""
from __future__ import annotations

import argparse
import json
import random
import signal
import subprocess
from pathlib import Path

import can
import pytest

from gimbal.messages import Message
from gimbal.messages.camera import CameraAction, CameraStatusQuery, CameraStatusReply
from gimbal.messages.external import FocusCalibration, FocusCalibrationReply
from gimbal.messages.motion import AnglesReply, GetAngles, PositionControl, SpeedControl
from gimbal.messages.settings import AngleLimitsReply, GetAngleLimits, SetAngleLimits
from gimbal.messages.telemetry import ParameterPush, PushControl, PushControlReply
from gimbal.messages.tlv_params import CalibrationStatusPush, SetUserParams, SetUserParamsReply, Tlv
from pipelines.cli import main
from pipelines.cli.gimbal_cmd import register
from tests.gimbal.scripted_peer import RELEASE, ZERO, ScriptedPeer, ends_with_stop, poll, speed_messages
from tests.support import ROOT, cli_command, free_udp_port, subprocess_env

DOC_EXAMPLE = "AA 1A 00 03 00 00 00 00 22 11 A2 42 0E 00 20 00 30 00 40 00 01 14 7B 40 97 BE"


def gimbal(channel: str, *args: str) -> int:
    return main(["gimbal", *args, "-i", "virtual", "-c", channel])


def test_print_packet_reproduces_the_documents_example(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["gimbal", "move", "--yaw", "3.2", "--roll", "4.8", "--pitch", "6.4", "--absolute",
                 "--time", "2", "--seq", "0x1122", "--print-packet"])
    assert code == 0
    assert capsys.readouterr().out.strip() == DOC_EXAMPLE


def test_print_packet_for_a_query_uses_the_given_seq(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["gimbal", "angles", "--kind", "joint", "--seq", "1", "--print-packet"]) == 0
    line = capsys.readouterr().out.strip()
    assert line.startswith("AA 13 00 03 00 00 00 00 01 00") and line.split()[12:15] == ["0E", "02", "02"]


@pytest.mark.parametrize("args,words", [
    (["move", "--yaw", "181"], "yaw_angle=1810 is outside -1800..1800"),
    (["speed", "--pitch", "-400"], "pitch_speed=-4000 is outside"),
    (["stiffness", "--pitch", "101", "--roll", "1", "--yaw", "1"], "pitch_stiffness=101"),
    (["focus", "position", "5000"], "position=5000 is outside 0..4095"),
    # 2.3.4.1: time_for_action "uint8_t 命令执行速度，单位 0.1s" (execution speed, unit 0.1 s):
    # 25.5 s at most, and the error says so in seconds as --time is given
    (["move", "--pitch", "10", "--time", "30"], "(30 s: allowed 0..25.5 s)"),
    # 2.3.3 Figure 6: "0x00000000 保留" (device ID 0 is reserved)
    (["version", "--device-id", "0"], "device_id=0 is outside 1..4294967295"),
    (["version", "--device-id", "0", "--announce", "0x01000000"], "device_id=0 is outside 1.."),
    (["user-params", "--param-table", "3"], "param_table=3 is outside 0..2"),
    (["move"], "give at least one of --yaw, --roll, --pitch"),
    (["angles", "--timeout", "inf"], "--timeout must be a number of seconds above 0"),
    (["angles", "--timeout", "nan"], "--timeout must be a number of seconds above 0"),
    (["angles", "--timeout=-1"], "--timeout must be a number of seconds above 0"),
    (["angles", "--timeout", "1e12"], "--timeout must be a number of seconds above 0"),
    (["angles", "--print-packet", "--seq", "0x12345"], "--seq must be 0..0xFFFF"),
    (["angles", "--print-packet", "--seq=-1"], "--seq must be 0..0xFFFF"),
])
def test_out_of_range_values_are_one_line_errors_before_anything_is_sent(
        channel: str, peer: ScriptedPeer, capsys: pytest.CaptureFixture[str], args: list[str],
        words: str) -> None:
    assert gimbal(channel, *args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("gimbaltrack gimbal: error:") and words in err
    assert peer.received == []


def test_angles_as_json(channel: str, peer: ScriptedPeer, capsys: pytest.CaptureFixture[str]) -> None:
    peer.answer(GetAngles, lambda m: AnglesReply(0, m.ctrl_byte, 123 * m.ctrl_byte, -45, 900))
    assert gimbal(channel, "angles", "--json") == 0
    assert json.loads(capsys.readouterr().out) == {
        "attitude": {"yaw": 12.3, "roll": -4.5, "pitch": 90.0},
        "joint": {"yaw": 24.6, "roll": -4.5, "pitch": 90.0}}


def test_angles_as_text_in_degrees(channel: str, peer: ScriptedPeer,
                                   capsys: pytest.CaptureFixture[str]) -> None:
    peer.answer(GetAngles, AnglesReply(0, 1, -1799, 0, 5))
    assert gimbal(channel, "angles", "--kind", "attitude") == 0
    assert capsys.readouterr().out.strip() == "attitude: yaw -179.9  roll 0.0  pitch 0.5"


def test_setting_one_limit_keeps_the_others(channel: str, peer: ScriptedPeer,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    peer.answer(GetAngleLimits, AngleLimitsReply(0, 100, 40, 90, 80, 20, 10))
    peer.answer(SetAngleLimits)
    assert gimbal(channel, "limits", "--yaw-max", "45", "--json") == 0
    assert peer.messages(SetAngleLimits) == [SetAngleLimits(1, 100, 40, 45, 80, 20, 10)]
    assert json.loads(capsys.readouterr().out)["limits"]["yaw_max"] == 45


def test_user_params_motors_off(channel: str, peer: ScriptedPeer,
                                capsys: pytest.CaptureFixture[str]) -> None:
    peer.answer(SetUserParams, SetUserParamsReply(0, (Tlv(0x23, b"\x01"),)))
    assert gimbal(channel, "user-params", "--motors-off", "--json") == 0
    assert peer.messages(SetUserParams)[0].tlvs == (Tlv(0x23, b"\x01"),)
    assert json.loads(capsys.readouterr().out) == {"set": {"motors_off": 1}}


def test_record_and_camera_status(channel: str, peer: ScriptedPeer,
                                  capsys: pytest.CaptureFixture[str]) -> None:
    peer.answer(CameraAction)
    peer.answer(CameraStatusQuery, CameraStatusReply(0, 2))
    assert gimbal(channel, "record", "start") == 0
    assert gimbal(channel, "camera-status", "--json") == 0
    assert peer.messages(CameraAction)[0].action == 0x0003
    assert capsys.readouterr().out.splitlines() == ["ok", '{"recording": true}']


def test_speed_streams_then_stops_and_releases(channel: str, peer: ScriptedPeer,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    peer.answer(SpeedControl)
    assert gimbal(channel, "speed", "--yaw", "12.5", "--duration", "0.3", "--json") == 0
    sent = speed_messages(peer)
    assert sent[-2:] == [ZERO, RELEASE]
    assert sent.count((125, 0, 0, 0x88)) >= 4  # resent while it lasted
    assert json.loads(capsys.readouterr().out)["reply_timeouts"] == 0


@pytest.mark.parametrize("duration", ["0", "0.05"])
def test_speed_too_short_to_see_a_reply_is_not_a_failure(channel: str, peer: ScriptedPeer, duration: str) -> None:
    """A run whose one reply was not collected yet once exited 1: 'did not answer of 1'."""
    peer.answer(SpeedControl)
    assert gimbal(channel, "speed", "--yaw", "5", "--duration", duration) == 0


@pytest.mark.parametrize("answer", ["nack", "silence"])
def test_speed_refused_or_unanswered_is_a_one_line_error(channel: str, peer: ScriptedPeer, answer: str,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    """Both once ended with exit 0 (silence: when shorter than the keep-alive's 10 missed replies)."""
    if answer == "nack":
        peer.nack(SpeedControl, 0x02)
    assert gimbal(channel, "speed", "--yaw", "5", "--duration", "0.2") == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and ("refused" if answer == "nack" else "did not answer") in err
    assert ends_with_stop(speed_messages(peer))  # resent while unanswered


@pytest.mark.parametrize("command", [["joystick", "--yaw", "5"], ["dial", "5"], ["watch"], ["speed"]])
@pytest.mark.parametrize("duration", ["nan", "inf", "-1"])
def test_a_duration_that_never_ends_or_is_negative_is_refused(channel: str, command: list[str], duration: str,
                                                              capsys: pytest.CaptureFixture[str]) -> None:
    """joystick and dial with --duration nan once held the stick push until killed."""
    with pytest.raises(SystemExit) as exited:
        gimbal(channel, *command, "--duration", duration)
    assert exited.value.code == 2 and "not a duration in seconds" in capsys.readouterr().err


def test_silence_is_a_one_line_error(channel: str, peer: ScriptedPeer,
                                     capsys: pytest.CaptureFixture[str]) -> None:
    assert gimbal(channel, "camera-status", "--timeout", "0.05") == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "did not answer" in err


def test_nack_is_a_one_line_error_with_its_meaning(channel: str, peer: ScriptedPeer,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    peer.nack(GetAngleLimits, 0x02)
    assert gimbal(channel, "limits") == 1
    assert "0x02 (command could not be executed)" in capsys.readouterr().err


def test_no_interface_anywhere_is_a_clear_error(monkeypatch: pytest.MonkeyPatch, tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(can, "rc", {})
    monkeypatch.setenv("HOME", str(tmp_path))
    for name in ("CAN_INTERFACE", "CAN_CHANNEL", "CAN_BITRATE", "CAN_CONFIG"):
        monkeypatch.delenv(name, raising=False)
    assert main(["gimbal", "angles"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no CAN interface configured" in err


def test_python_can_environment_configuration_is_used(
        channel: str, peer: ScriptedPeer, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv("CAN_INTERFACE", "virtual")
    monkeypatch.setenv("CAN_CHANNEL", channel)
    peer.answer(GetAngles, AnglesReply(0, 1, 10, 20, 30))
    assert main(["gimbal", "angles", "--kind", "attitude", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["attitude"]["yaw"] == 1.0


@pytest.mark.parametrize("args,bitrate", [([], 1_000_000), (["-b", "500000"], 500_000)])
def test_the_bitrate_is_the_documents_1_mbit_unless_given(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str],
        args: list[str], bitrate: int) -> None:
    monkeypatch.setattr(can, "rc", {})
    monkeypatch.setenv("HOME", str(tmp_path))
    for name in ("CAN_INTERFACE", "CAN_CHANNEL", "CAN_BITRATE", "CAN_CONFIG"):
        monkeypatch.delenv(name, raising=False)
    opened: list[dict[str, object]] = []

    def fake_bus(**kwargs: object) -> can.BusABC:
        opened.append(kwargs)
        raise can.CanInitializationError("no adapter")

    monkeypatch.setattr(can, "Bus", fake_bus)
    assert main(["gimbal", "angles", "-i", "gs_usb", "-c", "0", *args]) == 2
    # python-can's configuration, read once, is handed over whole (it makes a numeric channel an int)
    assert opened == [{"interface": "gs_usb", "channel": 0, "bitrate": bitrate, "ignore_config": True}]
    assert "no adapter" in capsys.readouterr().err


@pytest.mark.parametrize("args,words", [(["-i", "nosuchbus"], "unknown CAN interface"),
                                        (["-i", "socketcan", "-c", "nosuchcan0"], "cannot open"),
                                        (["-i", "kvaser"], "argument: 'channel'")])  # once a TypeError traceback
def test_bus_open_failures_are_one_line_errors(capsys: pytest.CaptureFixture[str], args: list[str],
                                               words: str) -> None:
    assert main(["gimbal", "angles", *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err


def test_python_cans_configuration_is_read_once_per_bus(monkeypatch: pytest.MonkeyPatch) -> None:
    from pipelines.cli.bus import open_can_bus

    real_load = can.util.load_config
    loads: list[object] = []
    monkeypatch.setattr(can.util, "load_config", lambda *a, **k: loads.append(a) or real_load(*a, **k))
    open_can_bus({"interface": "virtual", "channel": "once"}).shutdown()
    assert len(loads) == 1  # once for the error text, the default bitrate and can.Bus


def test_watch_shows_the_attitude_of_a_short_push_timed_from_its_start(
        channel: str, peer: ScriptedPeer, capsys: pytest.CaptureFixture[str]) -> None:
    def push_then_reply(message: Message) -> Message:
        peer.push(ParameterPush(0x01, 32, 48, 64))  # 25 bytes: attitude only, before the reply
        return PushControlReply()

    peer.answer(PushControl, push_then_reply)
    assert gimbal(channel, "watch", "--duration", "0.3", "--json") == 0
    first = json.loads(capsys.readouterr().out.splitlines()[0])
    assert first["push"] == "parameter_push" and first["t"] >= 0
    assert first["attitude"] == {"yaw": 3.2, "roll": 4.8, "pitch": 6.4} and "joint" not in first


def test_watch_names_the_calibration_state(channel: str, peer: ScriptedPeer,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    """Figure 30's states by name (0 idle, 1 running, 2 done, 3 error), not as a bare number."""
    def push_then_reply(message: Message) -> Message:
        peer.push(CalibrationStatusPush.of(1, 40))
        return PushControlReply()

    peer.answer(PushControl, push_then_reply)
    assert gimbal(channel, "watch", "--duration", "0.3", "--json") == 0
    pushes = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    status = next(p for p in pushes if p["push"] == "calibration_status_push")
    assert (status["state"], status["progress"]) == ("running", 40)


def test_watch_says_when_the_pushes_stop_and_fails_when_none_came(
        channel: str, peer: ScriptedPeer, capsys: pytest.CaptureFixture[str]) -> None:
    """A gimbal that stops pushing (switched off, push turned off elsewhere) once left watch silent,
    and a run in which nothing ever arrived exited 0."""
    def push_once_then_reply(message: Message) -> Message:
        peer.push(ParameterPush(0x01, 32, 48, 64))
        return PushControlReply()

    peer.answer(PushControl, push_once_then_reply)
    assert gimbal(channel, "watch", "--duration", "1.4", "--json") == 0
    captured = capsys.readouterr()
    assert len(captured.out.splitlines()) == 1
    assert captured.err == "gimbaltrack gimbal: no push for 1 s (is the gimbal on, and its push on?)\n"
    peer.answer(PushControl)
    assert gimbal(channel, "watch", "--duration", "0.3", "--json") == 1
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.splitlines() == [
        "gimbaltrack gimbal: error: no push arrived in 0.3 s (is the gimbal on, and its push on?)"]


def test_the_range_error_in_the_docs_is_what_the_cli_prints(capsys: pytest.CaptureFixture[str]) -> None:
    doc = (Path(__file__).parents[2] / "docs" / "gimbal-cli.md").read_text(encoding="utf-8")
    command = "$ gimbaltrack gimbal move --yaw 200 --print-packet\n"
    shown = doc.split(command, 1)[1].splitlines()[0]
    assert main(command.split()[2:]) == 2
    assert capsys.readouterr().err.strip() == shown


def test_the_python_example_in_the_docs_runs(channel: str, peer: ScriptedPeer,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    doc = (Path(__file__).parents[2] / "docs" / "gimbal-cli.md").read_text(encoding="utf-8")
    example = doc.split("```python\n", 1)[1].split("```", 1)[0]
    real_bus = 'GimbalClient(interface="socketcan", channel="can0")'
    assert real_bus in example
    peer.answer(GetAngles, AnglesReply(0, 1, 10, 20, 30))
    peer.answer(PositionControl)
    peer.answer(SpeedControl)
    exec(example.replace(real_bus, f'GimbalClient(interface="virtual", channel="{channel}")'), {})
    assert "Angles(kind='attitude', yaw=1.0, roll=2.0, pitch=3.0)" in capsys.readouterr().out


def test_the_simulated_gimbal_answers(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["gimbal", "version", "-i", "sim", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["device_id"] == 1
    assert main(["gimbal", "watch", "-i", "sim", "--duration", "0.3", "--json"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines and all(json.loads(line)["push"] == "parameter_push" for line in lines)  # once a last {}


def test_sigterm_to_a_streaming_process_stops_and_releases() -> None:
    """End to end in two processes over udp_multicast: the CLI streams speed, gets SIGTERM, and
    its last words on the bus are zero speed and release."""
    group = f"239.{random.randint(1, 254)}.{random.randint(1, 254)}.{random.randint(1, 254)}"
    port = free_udp_port()  # a port of its own: nothing else on the machine hears or sends on it
    bus = can.Bus(interface="udp_multicast", channel=group, port=port)
    with ScriptedPeer(bus) as peer:
        peer.answer(SpeedControl)
        child = subprocess.Popen(cli_command("gimbal", "speed", "--yaw", "15", "--duration", "60",
                                             "-i", "udp_multicast", "-c", group),
                                 stderr=subprocess.PIPE, text=True, env=subprocess_env(port))
        try:
            peer.wait_for(SpeedControl, 3, timeout=20.0, where=lambda m: m.yaw_speed == 150)
            child.send_signal(signal.SIGTERM)
            assert child.wait(timeout=20.0) == 128 + signal.SIGTERM, child.stderr.read()
        finally:
            child.kill()
        poll(lambda: speed_messages(peer)[-2:] == [ZERO, RELEASE])
    bus.shutdown()


def test_bus_and_output_options_work_before_or_after_the_command(capsys):
    """The issue's own spelling is ``gimbal -i <iface> -c <chan> COMMAND``; both orders must work."""
    from pipelines.cli import main

    assert main(["gimbal", "-i", "sim", "--json", "version"]) == 0
    before = json.loads(capsys.readouterr().out)
    assert main(["gimbal", "version", "-i", "sim", "--json"]) == 0
    after = json.loads(capsys.readouterr().out)
    assert before == after == {"device_id": 1, "version": "02.05.00.00"}


def test_can_ids_and_bitrates_are_checked() -> None:
    import argparse

    from pipelines.cli.common import parse_bitrate, parse_can_id

    assert parse_can_id("0x7FF") == 0x7FF and parse_can_id("546") == 0x222
    assert parse_bitrate("1000000") == 1_000_000
    for bad in ("0x800", "-1"):
        with pytest.raises(argparse.ArgumentTypeError, match="standard CAN id"):
            parse_can_id(bad)
    with pytest.raises(argparse.ArgumentTypeError, match="above 0"):
        parse_bitrate("-5")


def test_model_and_output_folders_are_checked(tmp_path: Path) -> None:
    import argparse

    from pipelines.cli.common import existing_dir, out_dir

    assert existing_dir(str(tmp_path)) == tmp_path and out_dir("out/x") == Path("out/x")
    with pytest.raises(argparse.ArgumentTypeError, match="no such folder"):
        existing_dir(str(tmp_path / "typo"))  # once quietly "no models"
    with pytest.raises(argparse.ArgumentTypeError, match="empty path"):
        out_dir("")  # once the current folder


@pytest.mark.parametrize("text", ["/", "//", "/tmp/..", "/./"])
def test_the_filesystem_root_is_no_output_folder(text: str) -> None:
    import argparse

    from pipelines.cli.common import out_dir

    with pytest.raises(argparse.ArgumentTypeError, match="filesystem root"):
        out_dir(text)  # once five outputs written into / (as root)


def test_an_output_folder_in_a_symlink_loop_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The root check resolved the path, and a symlink loop made that a RuntimeError traceback."""
    (tmp_path / "loop").symlink_to(tmp_path / "loop")
    # a good sequence: it is checked before the output folder is made
    assert main(["simulate", str(ROOT / "samples" / "demo.mp4"), "--tracker", "oracle",
                 "--out", str(tmp_path / "loop" / "x")]) == 2
    assert "cannot create output folder" in capsys.readouterr().err


def test_logging_options_also_after_the_command(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["decode", "--hex", "AA", "--verbose"]) == 0
    assert main(["--verbose", "decode", "--hex", "AA"]) == 0


def test_every_gimbal_argument_says_what_it_means_in_help() -> None:
    """Each option and positional of every ``gimbal`` command has help text (choices such as
    follow's lock/yaw/fpv or mode's orientations were listed without their meaning)."""
    parser = argparse.ArgumentParser()
    register(parser.add_subparsers())
    gimbal_parser = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices["gimbal"]
    commands = next(a for a in gimbal_parser._actions if isinstance(a, argparse._SubParsersAction))
    silent = [f"{name} {action.dest}" for name, sub in commands.choices.items() for action in sub._actions
              if not isinstance(action, argparse._HelpAction) and not action.help]
    assert silent == []


def test_a_focus_calibration_step_the_motor_reports_failed_exits_1(
        channel: str, peer: ScriptedPeer, capsys: pytest.CaptureFixture[str]) -> None:
    """2.3.4.19 Figure 33: the reply's "执行结果 ... 0x01: 执行失败" (execution result 1: failed)
    is a failure like a NACK: one line, exit 1 (it printed 'succeeded: False' and exited 0)."""
    peer.answer(FocusCalibration, FocusCalibrationReply(0, 0x02, 0x00, 0x01))
    assert gimbal(channel, "focus", "calibrate", "manual") == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "focus calibration manual" in err and "failed" in err
    peer.answer(FocusCalibration, FocusCalibrationReply(0, 0x02, 0x00, 0x00))
    assert gimbal(channel, "focus", "calibrate", "manual") == 0
