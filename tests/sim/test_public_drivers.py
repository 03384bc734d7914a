"""What five public DJI R SDK drivers put on the bus, and what our decoder and simulator make of it.

The byte strings are built here from each driver's documented behaviour (its field values, bit
constants and frame splitting, read in its repository; none of its code is used). Where a driver
follows the document the decoder must read it field for field; where it does not, the tests pin
down what docs/protocol.md says happens (the repository is named in each test)."""
from __future__ import annotations

import struct

import can
import pytest

from gimbal.log_decode import LogDecoder
from gimbal.messages.motion import AnglesReply, GetAngles, PositionControl
from gimbal.packet import Packet, encode_packet
from gimbal.sim import SimConfig
from gimbal.transport import CAN_FRAME_DATA, HOST_TX_ID
from tests.sim.helpers import wait_until

GIMBAL = 0x0E


def command(cmd_id: int, payload: bytes, seq: int, cmd_type: int = 0x03) -> bytes:
    """A command as every one of these drivers frames it: SOF, length, CmdType, ENC 0, RES 0, SEQ,
    CRC16, CmdSet/CmdID, payload, CRC32 (their CRC tables and inits are the document's)."""
    return encode_packet(Packet(cmd_type, seq, bytes((GIMBAL, cmd_id)) + payload))


def frames(raw: bytes) -> list[can.Message]:
    return [can.Message(arbitration_id=HOST_TX_ID, is_extended_id=False, data=raw[i:i + CAN_FRAME_DATA])
            for i in range(0, len(raw), CAN_FRAME_DATA)]


def decode(raw_frames: list[can.Message]) -> list[dict]:  # type: ignore[type-arg]
    decoder = LogDecoder()
    return [r for f in raw_frames for r in decoder.feed_frame(f)] + decoder.finish()


def reply_codes(make_sim, raw_frames: list[can.Message], config: SimConfig | None = None):  # type: ignore[no-untyped-def]
    """Send the frames to a fresh simulator; the return codes of the replies it sent, and it."""
    host, sim, bus = make_sim(config)
    for frame in raw_frames:
        bus.send(frame)
    codes: list[int] = []

    def collect() -> bool:
        packet = host.transport.recv(0.02)
        if isinstance(packet, Packet) and packet.is_reply:
            codes.append(packet.data[2])
        return False
    wait_until(collect, 0.4, step=0)
    return codes, sim


# --- ConstantRobotics/DJIR_SDK (C++) and CinelikeE/DJI-RS-SDK (C, RT-Thread) --------------------
# Both define BIT1 = 0x01 ... BIT7 = 0x40 (one position low), start with speed ctrl_byte |= BIT3
# (0x04, meant as bit 3 = 0x08) and enable speed control with BIT7 (0x40, meant as bit 7 = 0x80);
# position ctrl_byte |= BIT1 is 0x01 (absolute), right by coincidence.

OFF_BY_ONE_SPEED = (0x04, 0x44)  # default; after set_speed_mode(ENABLED, DISABLED)


@pytest.mark.parametrize("ctrl_byte", OFF_BY_ONE_SPEED)
def test_off_by_one_speed_bits_are_decoded_as_sent_and_flagged(ctrl_byte: int) -> None:
    raw = command(0x01, struct.pack("<hhhB", 300, 0, -150, ctrl_byte), seq=3)
    record = decode(frames(raw))[0]
    assert record["name"] == "speed_control"
    assert record["fields"] == {"yaw_speed": 300, "roll_speed": 0, "pitch_speed": -150, "ctrl_byte": ctrl_byte}
    assert "ctrl_byte" in record["out_of_range"]


@pytest.mark.parametrize("ctrl_byte", OFF_BY_ONE_SPEED)
def test_the_simulator_refuses_off_by_one_speed_bits_and_does_not_move(make_sim, ctrl_byte: int) -> None:
    codes, sim = reply_codes(make_sim, frames(command(0x01, struct.pack("<hhhB", 300, 0, 0, ctrl_byte), 3)))
    assert codes == [0x01]  # parse error, as the document says for a value it does not allow
    assert sim.state().speeds == (0.0, 0.0, 0.0) and not sim.state().speed_control


def test_their_position_and_angle_requests_follow_the_document(make_sim) -> None:
    move = command(0x00, struct.pack("<hhhBB", 100, 0, -200, 0x01, 2000 // 100), seq=4)  # move_to(..., 2000 ms)
    ask = command(0x02, bytes((0x01,)), seq=5)  # get_current_position
    records = decode(frames(move) + frames(ask))
    assert [r["name"] for r in records] == ["position_control", "get_angles"]
    assert records[0]["fields"] == {"yaw_angle": 100, "roll_angle": 0, "pitch_angle": -200, "ctrl_byte": 1,
                                    "time_for_action": 20}
    assert not any("out_of_range" in r or "error" in r for r in records)


def test_their_inverted_axis_bit_leaves_that_axis_alone(make_sim) -> None:
    # set_inverted_axis(YAW, true) sets BIT2 = 0x02: the document's "yaw invalid" bit, not an inversion
    raw = command(0x00, struct.pack("<hhhBB", 300, 0, 100, 0x01 | 0x02, 1), seq=6)
    assert decode(frames(raw))[0]["fields"]["ctrl_byte"] == 0x03
    codes, sim = reply_codes(make_sim, frames(raw))
    assert codes == [0x00]
    assert wait_until(lambda: sim.state().joint == (0.0, 0.0, 10.0), 1.0)  # pitch moved, yaw did not


def test_a_negative_speed_as_uint16_reads_as_the_negative_int16() -> None:
    # ConstantRobotics' set_speed takes uint16_t: -20.0 °/s arrives as 0xFF38, the document's int16 -200
    raw = command(0x01, struct.pack("<HHHB", 0xFF38, 0, 0, 0x80), seq=7)
    assert decode(frames(raw))[0]["fields"]["yaw_speed"] == -200


# --- ceinem/dji_rs2_ros_controller and Hibiki1020/dji_rs3pro_ros_controller (Python, ROS) -------
# Packets: CmdType 0x03, SEQ from 0x0003, position ctrl_byte 0x01 / time 0x14, speed ctrl_byte 0x80,
# get angles 0x01: all as the document says. They read a reply's angles at bytes 16, 18, 20 and
# take a raw value above 1800 as negative by subtracting 65538 (not 65536).

def test_ros_drivers_commands_decode_field_for_field() -> None:
    sent = [command(0x00, struct.pack("<3h2B", 450, 0, -300, 0x01, 0x14), seq=3),
            command(0x01, struct.pack("<3hB", -100, 0, 50, 0x80), seq=4),
            command(0x02, bytes((0x01,)), seq=5)]
    records = decode([f for raw in sent for f in frames(raw)])
    assert [r["name"] for r in records] == ["position_control", "speed_control", "get_angles"]
    assert records[1]["fields"] == {"yaw_speed": -100, "roll_speed": 0, "pitch_speed": 50, "ctrl_byte": 0x80}
    assert [r["seq"] for r in records] == [3, 4, 5]
    assert not any("out_of_range" in r for r in records)


def test_our_angle_reply_has_yaw_roll_pitch_where_they_read_them(make_client) -> None:
    client, sim = make_client()
    client.position(-10.0, 0.0, -20.5, time_s=0.1)
    assert wait_until(lambda: sim.state().joint == (-10.0, 0.0, -20.5), 2.0)
    raw = encode_packet(Packet.reply(GIMBAL, 0x02, AnglesReply(0, 2, -100, 0, -205).encode_payload(), 9))
    assert struct.unpack_from("<3h", raw, 16) == (-100, 0, -205)
    assert struct.unpack_from("<H", raw, 16)[0] - 65538 == -102  # their reading: 0.2° too far negative
    assert client.get_angles("joint").pitch == -20.5


def test_hibiki1020_set_limits_under_python3_is_refused(make_sim) -> None:
    # set_hyperparams packs seven limit bytes, then turns each into struct.unpack('<1B', b'i'):
    # under Python 3 every byte is 0x69, so ctrl_byte 0x69 and every limit 105
    raw = command(0x03, bytes([0x69] * 7), seq=3)
    record = decode(frames(raw))[0]
    assert record["name"] == "set_angle_limits" and record["fields"]["ctrl_byte"] == 0x69
    assert "out_of_range" in record
    codes, sim = reply_codes(make_sim, frames(raw))
    assert codes == [0x01] and sim.state().limits["pitch_max"] == 145


def test_hibiki1020_intended_set_limits_is_a_no_operation(make_sim) -> None:
    # what the comment says was meant: return_code 0 first, i.e. ctrl_byte 0x00, "no operation"
    raw = command(0x03, bytes((0, 30, 0, 0, 0, 30, 0)), seq=3)
    assert "out_of_range" not in decode(frames(raw))[0]
    codes, sim = reply_codes(make_sim, frames(raw))
    assert codes == [0x00] and sim.state().limits["pitch_max"] == 145  # nothing changed


# --- Blue-Hill-Tech/DJI_RS2 (python-can) ----------------------------------------------------------
# Payloads as the document says. Its send_data sends, inside the loop over the full 8-byte frames,
# every frame of the packet as filled so far: unfilled frames go out empty (DataLen 0) and the
# last frame early, with the bytes that follow the frames filled so far.

def blue_hill_frames(raw: bytes) -> list[can.Message]:
    full, left = divmod(len(raw), CAN_FRAME_DATA)
    buffers = [b""] * (full + (1 if left else 0))
    sent: list[bytes] = []
    for i in range(full):
        buffers[i] = raw[i * 8:i * 8 + 8]
        if left:
            buffers[-1] = raw[(i + 1) * 8:(i + 1) * 8 + left]
        sent.extend(buffers)
    return [can.Message(arbitration_id=HOST_TX_ID, is_extended_id=False, data=data) for data in sent]


def test_blue_hill_repeated_frames_give_one_command_once(make_sim) -> None:
    move = command(0x00, struct.pack("<3h2B", 0, 0, 100, 0x00, 5), seq=3)  # relative: +10° pitch
    sent = blue_hill_frames(move)
    assert len(sent) == 12 and sum(len(f.data) == 0 for f in sent) == 3
    records = decode(sent)
    assert [r.get("name") for r in records if "error" not in r] == ["position_control"]
    assert {r["error"] for r in records if "error" in r} == {"crc16", "truncated"}  # the early copies
    codes, sim = reply_codes(make_sim, sent)
    assert codes == [0x00]  # answered once: the relative move is not doubled
    assert wait_until(lambda: sim.state().joint == (0.0, 0.0, 10.0), 1.0)
    ask = command(0x02, bytes((0x01,)), seq=4)
    assert [r.get("name") for r in decode(blue_hill_frames(ask)) if "error" not in r] == ["get_angles"]


def test_the_document_example_packet_is_what_each_driver_builds() -> None:
    # the document's worked example, the packet every driver above reproduces for this intent
    example = bytes.fromhex("AA1A000300000000221 1A2420E00200030004000011 47B4097BE".replace(" ", ""))
    assert command(0x00, struct.pack("<3h2B", 32, 48, 64, 0x01, 20), seq=0x1122) == example
    assert PositionControl.decode_payload(example[14:-4]) == PositionControl(32, 48, 64, 1, 20)
    assert GetAngles.decode_payload(b"\x01") == GetAngles(1)


# --- met in ports of these drivers: "push off" sent as 0x00 -----------------------------------
# The document's push control (0x0E/0x07) ctrl_byte is 0x01 on, 0x02 off, 0x00 "no operation".

def test_push_off_sent_as_0x00_is_a_valid_no_operation_and_the_pushes_go_on(make_sim) -> None:
    push_on, push_off_as_zero = command(0x07, b"\x01", seq=5), command(0x07, b"\x00", seq=6)
    records = decode(frames(push_off_as_zero))
    assert [(r["name"], r["fields"]) for r in records] == [("push_control", {"ctrl_byte": 0x00})]
    assert not any("error" in r or r.get("out_of_range") for r in records)
    codes, sim = reply_codes(make_sim, frames(push_on) + frames(push_off_as_zero))
    assert codes == [0x00, 0x00]  # both accepted
    assert sim.state().push_enabled  # the 0x00 changed nothing: the gimbal keeps pushing
