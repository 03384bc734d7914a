"""Firmware variants, each both ways: the simulator sends it, the client and the decoder read it.

Legacy attitude field order (document yaw, roll, pitch; ArduPilot's yaw, pitch, roll), pushes
with and without the reply bit, get requests without their payload, encrypted packets."""
from __future__ import annotations

import json
import subprocess

import can
import pytest

from gimbal.client import GimbalClient
from gimbal.errors import GimbalTimeoutError
from gimbal.log_decode import LogDecoder
from gimbal.messages import decode_message, message_packet
from gimbal.messages.motion import AnglesReply, GetAngles
from gimbal.messages.settings import AngleLimitsReply, GetAngleLimits, GetMotorStiffness
from gimbal.messages.telemetry import ParameterPush, PushControl
from gimbal.messages.tlv_params import CalibrationStatusPush, GetUserParams
from gimbal.packet import Packet, encode_packet
from gimbal.sim import SimConfig
from gimbal.sim.checks import FieldError
from gimbal.sim.slcan_pty import virtual_pair
from gimbal.transport import CAN_FRAME_DATA, HOST_RX_ID, HOST_TX_ID, CanTransport
from tests.sim.helpers import wait_until
from tests.support import ROOT, cli_command, subprocess_env

POSE = (10.0, 5.0, -20.0)  # yaw, roll, pitch: roll and pitch differ, so a swap shows


def move_to_pose(client: GimbalClient, sim) -> None:  # type: ignore[no-untyped-def]
    client.position(*POSE, time_s=0.1)
    assert wait_until(lambda: sim.state().joint == POSE, 2.0)


# --- legacy attitude order --------------------------------------------------------------------

def test_legacy_angle_reply_bytes_follow_the_order_and_read_back_in_it() -> None:
    reply = AnglesReply(0, 2, 100, 50, -200)
    document = message_packet(reply, 7, legacy=True)
    ypr = message_packet(reply, 7, legacy=True, legacy_order="ypr")
    assert document.data == bytes.fromhex("00 02 6400 3200 38ff")  # yaw, roll, pitch
    assert ypr.data == bytes.fromhex("00 02 6400 38ff 3200")  # yaw, pitch, roll
    assert decode_message(ypr, GetAngles(2), "ypr") == reply
    assert decode_message(document, GetAngles(2)) == reply
    swapped = decode_message(ypr, GetAngles(2))  # read in the other order: roll and pitch trade places
    assert (swapped.roll, swapped.pitch) == (-200, 50)
    latest = message_packet(reply, 7)  # the latest layout always follows the document
    assert decode_message(latest, GetAngles(2), "ypr") == reply


@pytest.mark.parametrize("order", ["document", "ypr"])
def test_client_reads_a_legacy_gimbal_in_its_order(make_client, order: str) -> None:
    client, sim = make_client(SimConfig(legacy=True, legacy_attitude_order=order), legacy_attitude_order=order)
    move_to_pose(client, sim)
    joint = client.get_angles("joint")
    assert (joint.yaw, joint.roll, joint.pitch) == POSE


def test_client_in_the_other_order_swaps_roll_and_pitch(make_client) -> None:
    client, sim = make_client(SimConfig(legacy=True, legacy_attitude_order="ypr"))
    move_to_pose(client, sim)
    joint = client.get_angles("joint")
    assert (joint.yaw, joint.roll, joint.pitch) == (10.0, -20.0, 5.0)


def test_the_order_is_checked_where_it_is_given(make_sim) -> None:
    with pytest.raises(ValueError, match="ypr"):
        LogDecoder(legacy_attitude_order="pyr")
    with pytest.raises(FieldError, match="legacy_attitude_order"):
        SimConfig(legacy_attitude_order="yaw-pitch-roll")
    _, _, bus = make_sim()
    with pytest.raises(ValueError, match="document, ypr"):
        GimbalClient(bus, legacy_attitude_order="PYR")


def _frames(packet: Packet, can_id: int) -> list[can.Message]:
    raw = encode_packet(packet)
    return [can.Message(arbitration_id=can_id, is_extended_id=False, data=raw[i:i + CAN_FRAME_DATA])
            for i in range(0, len(raw), CAN_FRAME_DATA)]


def _legacy_conversation() -> tuple[Packet, Packet]:
    query = message_packet(GetAngles(1), 0x40)
    reply = message_packet(AnglesReply(0, 1, 100, 50, -200), 0x40, legacy=True, legacy_order="ypr")
    return query, reply


@pytest.mark.parametrize(("order", "roll", "pitch"), [("ypr", 50, -200), ("document", -200, 50)])
def test_log_decoder_reads_legacy_angle_replies_in_its_order(order: str, roll: int, pitch: int) -> None:
    query, reply = _legacy_conversation()
    decoder = LogDecoder(legacy_attitude_order=order)
    records = [r for p, i in ((query, 0x223), (reply, 0x222)) for f in _frames(p, i) for r in decoder.feed_frame(f)]
    assert records[1]["layout"] == "legacy" and records[1]["request_seq"] == 0x40
    assert (records[1]["fields"]["roll"], records[1]["fields"]["pitch"]) == (roll, pitch)


def test_decode_and_replay_take_the_order_on_the_command_line(tmp_path) -> None:
    query, reply = _legacy_conversation()
    hexes = [encode_packet(p).hex() for p in (query, reply)]
    done = subprocess.run(cli_command("decode", "--legacy-order", "ypr", "--hex", hexes[0], "--hex", hexes[1]),
                          capture_output=True, text=True, timeout=60, cwd=ROOT, env=subprocess_env())
    assert done.returncode == 0, done.stderr
    fields = json.loads(done.stdout.splitlines()[1])["fields"]
    assert (fields["roll"], fields["pitch"]) == (50, -200)
    log = tmp_path / "legacy.log"
    lines = [f"({0.001 * n:.6f}) vcan0 {f.arbitration_id:03X}#{bytes(f.data).hex().upper()}"
             for n, f in enumerate(_frames(query, 0x223) + _frames(reply, 0x222))]
    log.write_text("\n".join(lines) + "\n")
    for order, expected in (("ypr", (50, -200)), ("document", (-200, 50))):
        done = subprocess.run(cli_command("replay", str(log), "--json", "--legacy-order", order),
                              capture_output=True, text=True, timeout=60, cwd=ROOT, env=subprocess_env())
        assert done.returncode == 0, done.stderr
        record = next(json.loads(line) for line in done.stdout.splitlines() if '"get_angles_reply"' in line)
        assert (record["fields"]["roll"], record["fields"]["pitch"]) == expected


# --- pushes with and without the reply bit ---------------------------------------------------

@pytest.mark.parametrize("reply_bit", [False, True])
def test_pushes_with_or_without_the_reply_bit_reach_client_and_decoder(make_sim, reply_bit: bool) -> None:
    host, sim, bus = make_sim(SimConfig(push_reply_bit=reply_bit, calibration_s=0.2, calibration_push_hz=20))
    with GimbalClient(bus) as client:
        calibration: list[CalibrationStatusPush] = []
        client.on_push(CalibrationStatusPush, lambda m, t: calibration.append(m))
        client.set_push(True)
        assert wait_until(lambda: client.latest(ParameterPush) is not None, 1.0)
        client.auto_calibration(True)
        assert wait_until(lambda: calibration and calibration[-1].progress == 100, 2.0)
        client.set_push(False)
        assert client.stats["bad_pushes"] == 0 and client.stats["stale_replies"] == 0
    push = message_packet(sim._model.parameter_push(), 3, 0x20 if reply_bit else None)
    assert push.is_reply is reply_bit
    records = LogDecoder().feed_bytes(encode_packet(push), "gimbal->host")
    assert records[0]["name"] == "parameter_push" and records[0]["kind"] == "push"


def test_the_simulator_sets_the_reply_bit_on_pushes_only_when_told(make_sim) -> None:
    for reply_bit in (False, True):
        host, _, _ = make_sim(SimConfig(push_reply_bit=reply_bit))
        seen: list[int] = []
        original = host._note
        host._note = lambda packet: (seen.append(packet.cmd_type), original(packet))  # type: ignore[method-assign]
        host.ask(PushControl(1))
        host.collect(0.1)
        assert seen and set(seen) == {0x20 if reply_bit else 0x00}


# --- get requests without their payload --------------------------------------------------------

@pytest.mark.parametrize("cls", [GetAngleLimits, GetMotorStiffness, GetUserParams])
def test_decoder_names_empty_get_requests_as_outside_the_document(cls) -> None:  # type: ignore[no-untyped-def]
    decoder = LogDecoder()
    empty = Packet.command(cls.CMD_SET, cls.CMD_ID, b"", 9)
    record = decoder.feed_bytes(encode_packet(empty), "host->gimbal")[0]
    assert record["name"] == cls.NAME and "error" not in record
    assert "without its payload" in record["outside_document"]
    reply = message_packet(cls.REPLY(0x01), 9, legacy=True)  # a legacy NACK pairs with it
    answer = decoder.feed_bytes(encode_packet(reply), "gimbal->host")[0]
    assert answer["name"] == cls.REPLY.NAME and answer["request_seq"] == 9
    whole = decoder.feed_bytes(encode_packet(message_packet(cls(), 10)), "host->gimbal")[0]
    assert whole["name"] == cls.NAME and "outside_document" not in whole


def test_only_a_lenient_simulator_answers_empty_get_requests(make_sim) -> None:
    empty = Packet.command(GetAngleLimits.CMD_SET, GetAngleLimits.CMD_ID, b"", 0x51)
    for lenient, code in ((False, 0x01), (True, 0x00)):
        host, sim, _ = make_sim(SimConfig(lenient=lenient))
        host.transport.send(empty)
        reply = _reply_to(host, 0x51)
        decoded = decode_message(reply, GetAngleLimits)
        assert isinstance(decoded, AngleLimitsReply) and decoded.return_code == code
        if lenient:
            assert decoded.yaw_max == 179 and sim.state().faults["empty_get_requests"] == 1


def _reply_to(host, seq: int, timeout: float = 0.5) -> Packet | None:  # type: ignore[no-untyped-def]
    found: list[Packet] = []

    def arrived() -> bool:
        packet = host.transport.recv(0.01)
        if isinstance(packet, Packet) and packet.is_reply and packet.seq == seq:
            found.append(packet)
        return bool(found)
    wait_until(arrived, timeout, step=0)
    return found[0] if found else None


# --- encrypted packets -------------------------------------------------------------------------

def test_the_simulator_never_parses_an_encrypted_command(make_sim) -> None:
    host, sim, _ = make_sim()
    command = message_packet(GetAngles(1), 0x61)
    host.transport.send(Packet(command.cmd_type, 0x62, command.data, enc=0x20))
    assert _reply_to(host, 0x62, 0.3) is None
    assert sim.state().faults["framer_encrypted"] > 0 and not sim.state().commands
    host.transport.send(command)  # the same command in the clear is answered
    assert _reply_to(host, 0x61) is not None


def test_the_client_never_parses_encrypted_replies_or_pushes() -> None:
    host_bus, device_bus = virtual_pair()  # no simulator: only these scripted packets answer
    gimbal_side = CanTransport(device_bus, tx_id=HOST_RX_ID, rx_id=HOST_TX_ID)
    push = message_packet(ParameterPush(1, 100, 0, 0), 1)
    try:
        with GimbalClient(host_bus, timeout=0.1, retries=0) as client:
            gimbal_side.send(Packet(push.cmd_type, 1, push.data, enc=0x20))
            assert wait_until(lambda: client.stats["dropped_encrypted"] > 0, 1.0)
            assert client.latest(ParameterPush) is None
            with pytest.raises(GimbalTimeoutError):
                client.get_angles()  # nobody answers in the clear
            gimbal_side.send(push)
            assert wait_until(lambda: client.latest(ParameterPush) is not None, 1.0)
    finally:
        host_bus.shutdown()
        device_bus.shutdown()
