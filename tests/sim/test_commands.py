"""Every command of the document, over a virtual bus: the right reply, the right state change."""
from __future__ import annotations

import time

import pytest

from gimbal.errors import ReturnCodeError
from gimbal.messages import Kind, all_message_classes, camera, decode_message, motion, settings, tlv_params
from gimbal.messages.tlv_params import (
    AutoCalibration, CALIBRATION_DONE, CALIBRATION_RUNNING, autotune, describe_user_param, motors_off,
    param_table, roll360_mode,
)
from gimbal.packet import NO_REPLY, Packet, REPLY_OPTIONAL
from gimbal.sim import SimConfig
from gimbal.sim.model import GimbalModel
from tests.sim.helpers import wait_until


COMMANDS = [c for c in all_message_classes() if c.KIND is Kind.COMMAND]
HOST_PUSHES = [c for c in all_message_classes() if c.KIND is Kind.PUSH and c.SENDER.value == "host"]


def test_the_document_has_21_commands_and_all_are_covered() -> None:
    keys = {(c.CMD_SET, c.CMD_ID) for c in all_message_classes()}
    assert len(keys) == 21
    assert keys == {(c.CMD_SET, c.CMD_ID) for c in COMMANDS + HOST_PUSHES} | {(0x0E, 0x08), (0x0E, 0x10)}


@pytest.mark.parametrize("cls", COMMANDS, ids=lambda c: c.NAME)
def test_every_command_gets_its_reply_with_the_same_seq(sim_host, cls) -> None:
    host, _ = sim_host
    message = cls((param_table(1),)) if cls is tlv_params.SetUserParams else cls()
    packet = host.ask_packet(message)
    assert packet is not None and packet.is_reply and packet.data[:2] == bytes((cls.CMD_SET, cls.CMD_ID))
    reply = decode_message(packet, message)
    assert type(reply) is cls.REPLY and reply.return_code == 0


@pytest.mark.parametrize("cls", HOST_PUSHES, ids=lambda c: c.NAME)
def test_host_pushes_are_never_answered_but_counted(sim_host, cls) -> None:
    host, sim = sim_host
    assert host.ask_packet(cls(), timeout=0.15) is None
    assert sim.state().commands[cls.NAME] == 1


def test_reply_policy_of_cmd_type(sim_host) -> None:
    host, sim = sim_host
    assert host.ask_packet(camera.CameraAction(camera.CameraActionCode.TAKE_PHOTO), 0.15, cmd_type=NO_REPLY) is None
    assert sim.state().photos == 1
    assert host.ask(camera.CameraStatusQuery(), cmd_type=REPLY_OPTIONAL).ok


def test_legacy_firmware_omits_cmdset_and_cmdid(make_sim) -> None:
    host, _, _ = make_sim(SimConfig(legacy=True))
    packet = host.ask_packet(motion.GetAngles(motion.ANGLES_JOINT))
    assert packet.data[0] == 0 and len(packet.data) == 8  # return code, data_type, 3 × int16
    assert host.ask(motion.GetAngles(motion.ANGLES_JOINT)).data_type == motion.ANGLES_JOINT


def test_unparsable_payloads_get_0x01(sim_host) -> None:
    host, sim = sim_host
    cases = [Packet.command(0x0E, 0x00, b"\x01\x02\x03", 1),  # too short
             Packet.command(0x0E, 0x01, bytes(6) + b"\x40", 2),  # reserved ctrl bits (the off-by-one port)
             Packet.command(0x0E, 0x00, (4000).to_bytes(2, "little", signed=True) + bytes(4) + b"\x01\x0a", 3),
             Packet.command(0x0E, 0x30, b"\x00", 4),  # no such command
             Packet.command(0x0D, 0x00, b"\x09\x00", 5)]  # no such camera action
    for packet in cases:
        host.transport.send(packet)
        reply = host.transport.recv(0.3)
        assert isinstance(reply, Packet) and reply.seq == packet.seq
        assert reply.data == packet.data[:2] + b"\x01"
    assert sim.state().faults["unparsable"] == len(cases)
    assert not sim.state().moving


def test_foreign_ids_are_ignored(sim_host) -> None:
    host, sim = sim_host
    from gimbal.transport import CanTransport
    other = CanTransport(host.transport.bus, tx_id=0x224, rx_id=0x222)
    other.send(Packet.command(0x0D, 0x01, b"\x01", 9))
    assert host.transport.recv(0.15) is None
    assert sim.state().faults["foreign_frames"] >= 1


def test_configurable_ids(make_sim) -> None:
    _, _, bus = make_sim(SimConfig(rx_id=0x323, tx_id=0x322))
    from gimbal.client import GimbalClient
    with GimbalClient(bus, tx_id=0x323, rx_id=0x322) as client:
        assert client.camera_status() is False


def test_angle_limits_and_stiffness_round_trip(make_client) -> None:
    client, sim = make_client()
    client.set_angle_limits(pitch_max=60, pitch_min=20, yaw_max=90, yaw_min=45, roll_max=10, roll_min=5)
    limits = client.get_angle_limits()
    assert (limits.pitch_max, limits.pitch_min, limits.yaw_max, limits.yaw_min, limits.roll_max,
            limits.roll_min) == (60, 20, 90, 45, 10, 5)
    client.set_stiffness(pitch=10, roll=20, yaw=30)
    stiffness = client.get_stiffness()  # the get reply orders pitch, yaw, roll
    assert (stiffness.pitch_stiffness, stiffness.yaw_stiffness, stiffness.roll_stiffness) == (10, 30, 20)
    assert sim.state().stiffness == {"pitch": 10, "roll": 20, "yaw": 30}


def test_user_params_and_motors_off(make_client) -> None:
    client, sim = make_client()
    echoed = client.set_user_params([param_table(2), roll360_mode(2)])
    assert [describe_user_param(t) for t in echoed] == [{"param_table": 2}, {"roll360_mode": "roll360"}]
    client.set_user_params([motors_off(True)])
    assert [describe_user_param(t) for t in client.get_user_params()] == [
        {"param_table": 2}, {"roll360_mode": "roll360"}, {"motors_off": 1}]
    assert not sim.state().motors_on
    for motion_call in (lambda: client.position(10, 0, 0, time_s=0.5), lambda: client.speed(10, 0),
                        client.recenter, client.selfie):
        with pytest.raises(ReturnCodeError) as err:
            motion_call()
        assert err.value.return_code == 0x02
    client.joystick(yaw=15000, pitch=0)
    time.sleep(0.1)
    assert not sim.state().moving
    client.set_user_params([motors_off(False)])
    client.position(10, 0, 0, time_s=0.2)
    assert wait_until(lambda: sim.state().joint[0] == 10.0, 1.0)


def test_work_mode_follow_mode_activetrack_and_version(make_client) -> None:
    client, sim = make_client(SimConfig(version=0x01020304))
    client.set_work_mode("portrait")
    assert sim.state().orientation_deg == 90
    client.set_work_mode("toggle")
    assert sim.state().orientation_deg == 0
    client.set_work_mode("landscape-flipped")
    assert sim.state().orientation_deg == 180
    for name, code in (("lock", 0x00), ("fpv", 0x03), ("yaw", 0x02)):
        client.set_follow_mode(name)
        assert sim.state().follow_mode == code
    client.activetrack_toggle()
    assert sim.state().activetrack
    client.activetrack_toggle()
    assert not sim.state().activetrack
    reply = client.version()
    assert (reply.device_id, reply.version_text) == (1, "01.02.03.04")
    with pytest.raises(ReturnCodeError):
        client.version(device_id=2)
    client.push_version(0x1234, 0x0A0B0C0D)
    assert wait_until(lambda: sim.state().external_versions == {0x1234: 0x0A0B0C0D}, 0.5)


def test_recenter_and_selfie_move_over_time(make_client) -> None:
    client, sim = make_client(SimConfig(initial_joint_deg=(50.0, 10.0, -20.0)))
    client.recenter()
    time.sleep(0.1)
    assert sim.state().moving and 30.0 < sim.state().joint[0] < 50.0
    assert wait_until(lambda: sim.state().joint == (0.0, 0.0, 0.0), 1.0)
    client.selfie()
    assert wait_until(lambda: not sim.state().moving, 2.5)
    assert sim.state().joint[0] == 179.0 and sim.state().selfie  # yaw stops at the 179° user limit
    client.selfie()
    assert wait_until(lambda: sim.state().joint[0] == 0.0, 2.5)


def test_joystick_moves_like_speed_control(make_client) -> None:
    client, sim = make_client()
    client.joystick(yaw=3000, pitch=-1500)  # 0.2 and -0.1 of full scale (150 °/s)
    time.sleep(0.2)
    state = sim.state()
    assert state.speeds[0] == 30.0 and state.speeds[2] == -15.0
    assert wait_until(lambda: not sim.state().moving, 1.0)


def test_focus_motor_position_dial_and_calibration(make_client) -> None:
    client, sim = make_client()
    assert client.focus_read().calibration_state == 0x01
    assert not client.focus_calibration("manual")  # no travel marks yet
    client.focus_position(2000)
    assert wait_until(lambda: client.focus_read().position == 2000, 1.0)
    assert client.focus_calibration("set-min")
    client.focus_position(3000)
    assert wait_until(lambda: client.focus_read().position == 3000, 1.0)
    assert client.focus_calibration("set-max") and client.focus_calibration("manual")
    client.focus_position(4095)
    time.sleep(0.5)
    read = client.focus_read()
    assert (read.calibration_state, read.position) == (0x03, 3000)  # clamped to the calibrated span
    client.dial(-2048)
    time.sleep(0.2)
    assert 2000 <= client.focus_read().position < 2990
    assert client.focus_calibration("auto")
    assert client.focus_read().calibration_state == 0x02
    assert client.focus_calibration("stop") and client.focus_read().calibration_state == 0x01
    assert not client.focus_calibration("stop")


def test_auto_calibration_pushes_progress_then_done(make_client) -> None:
    client, sim = make_client(SimConfig(calibration_s=0.6))
    seen: list[tuple[int, int]] = []
    client.on_push(tlv_params.CalibrationStatusPush, lambda m, t: seen.append((m.state, m.progress)))
    client.auto_calibration(start=True)
    time.sleep(0.1)
    with pytest.raises(ReturnCodeError):
        client.speed(10, 0)  # busy calibrating
    assert wait_until(lambda: seen and seen[-1] == (2, 100), 1.5)
    progress = [p for s, p in seen if s == 1]
    assert len(progress) >= 4 and progress == sorted(progress) and progress[0] < 20
    assert sim.state().calibration == (2, 100)
    client.speed(10, 0)


def test_camera_without_camera_fails(make_client) -> None:
    client, _ = make_client(SimConfig(camera_connected=False))
    with pytest.raises(ReturnCodeError):
        client.start_recording()


def test_state_is_telemetry(make_client) -> None:
    import json
    client, sim = make_client()
    client.start_recording()
    record = json.loads(json.dumps(sim.state().as_dict()))
    assert record["recording"] is True and record["commands"]["camera_action"] == 1
    assert record["sent"]["camera_action_reply"] == 1


# Auto-calibration (0x0F) started while it runs fails with 0x02 and does not restart it.
def test_a_second_start_while_running_fails_and_keeps_the_first_schedule() -> None:
    """Started at 0 s (3 s run), started again at 1 s: 0x02, still done at 3 s, not 4 s."""
    model = GimbalModel(SimConfig(calibration_s=3.0), 0.0)
    assert model.handle(AutoCalibration((autotune(True),)), 0.0).ok
    reply = model.handle(AutoCalibration((autotune(True),)), 1.0)
    assert reply.return_code == 0x02
    model.advance(2.0)
    assert model.calibration[0] == CALIBRATION_RUNNING and model.calibration[1] >= 60
    pushes = model.advance(3.05)
    assert model.calibration == (CALIBRATION_DONE, 100)
    assert any(isinstance(m, tlv_params.CalibrationStatusPush) for m in pushes)


def test_start_after_done_is_accepted() -> None:
    """Only a running calibration blocks a start: once done, a new one may begin."""
    model = GimbalModel(SimConfig(calibration_s=1.0), 0.0)
    assert model.handle(AutoCalibration((autotune(True),)), 0.0).ok
    model.advance(1.5)
    assert model.handle(AutoCalibration((autotune(True),)), 1.5).ok
    model.advance(1.6)
    assert model.calibration[0] == CALIBRATION_RUNNING


# Work mode (0x0D) orientation changes are motion: refused with 0x02 while the motors are off.
def test_portrait_with_motors_off_fails_and_keeps_the_orientation() -> None:
    """Motors off: portrait (0x03) replies 0x02, orientation stays 0°; back on, it is accepted."""
    model = GimbalModel(SimConfig(), 0.0)
    assert model.handle(tlv_params.SetUserParams((motors_off(True),)), 0.0).ok
    assert model.handle(settings.SetWorkMode(orientation=0x03), 0.0).return_code == 0x02
    assert model.orientation == 0
    assert model.handle(settings.SetWorkMode(orientation=0x00), 0.0).ok  # no orientation change: fine
    assert model.handle(tlv_params.SetUserParams((motors_off(False),)), 0.1).ok
    assert model.handle(settings.SetWorkMode(orientation=0x03), 0.1).ok
    assert model.orientation == 90


# A position move ends the selfie pose: the next selfie command turns yaw round again, not back to 0.
def test_selfie_after_a_position_move_goes_to_the_selfie_yaw_again() -> None:
    """Selfie (yaw 179°, the default limit), position to yaw 30°, selfie again: yaw 179°, selfie set."""
    model = GimbalModel(SimConfig(), 0.0)
    assert model.handle(settings.RecenterSelfie(action=settings.SELFIE), 0.0).ok
    model.advance(2.0)  # 179° at 100 °/s
    assert model.joint()[0] == 179.0 and model.selfie
    assert model.handle(motion.PositionControl(yaw_angle=300, time_for_action=5), 2.0).ok
    model.advance(4.0)
    assert model.joint()[0] == 30.0 and not model.selfie
    assert model.handle(settings.RecenterSelfie(action=settings.SELFIE), 4.0).ok
    model.advance(6.0)
    assert model.joint()[0] == 179.0 and model.selfie


# Packets with the reply bit set that reach the simulator are ignored and counted, never executed.
def test_a_reply_shaped_camera_action_is_not_executed(sim_host) -> None:  # type: ignore[no-untyped-def]
    """A "start recording" payload sent with the reply bit: no reply, not recording, counted."""
    host, sim = sim_host
    payload = int(camera.CameraActionCode.START_RECORDING).to_bytes(2, "little")
    host.transport.send(Packet.reply(0x0D, 0x00, payload, 7))
    assert host.transport.recv(0.15) is None
    time.sleep(0.02)
    state = sim.state()
    assert not state.recording and state.commands.get("camera_action", 0) == 0
    assert state.faults["replies_received"] == 1
