"""gimbal.log_decode: both directions, reply matching, every kind of drop, any log format."""
from __future__ import annotations

import json
from pathlib import Path

import can
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gimbal.log_decode import (GIMBAL_TO_HOST, HOST_TO_GIMBAL, REPLY_WINDOW, LogDecoder,
                               decode_frames, decode_log_file)
from gimbal.messages import Message, message_packet
from gimbal.messages.external import (FocusCalibration, FocusCalibrationReply, FocusPositionQuery,
                                      FocusPositionReply)
from gimbal.messages.motion import AnglesReply, GetAngles, SpeedControl, SpeedControlReply
from gimbal.messages.telemetry import ParameterPush
from gimbal.packet import Packet, encode_packet
from gimbal.transport import packet_frames

PUSH = ParameterPush(7, 1, 2, 3, 4, 5, 6, 145, 55, 179, 179, 30, 30, 50, 50, 50)


def frames_of(message: Message, seq: int, can_id: int, t: float, legacy: bool = False,
              cmd_type: int | None = None) -> list[can.Message]:
    raw = encode_packet(message_packet(message, seq, cmd_type=cmd_type, legacy=legacy))
    frames = packet_frames(raw, can_id)
    for i, frame in enumerate(frames):
        frame.timestamp = t + i * 0.0001
    return frames


def conversation(legacy: bool = False) -> list[can.Message]:
    return [*frames_of(SpeedControl(100, 0, -50), 1, 0x223, 10.0),
            *frames_of(GetAngles(1), 2, 0x223, 10.001),
            *frames_of(SpeedControlReply(0), 1, 0x222, 10.003, legacy),
            *frames_of(AnglesReply(0, 1, -312, 4, 87), 2, 0x222, 10.004, legacy),
            *frames_of(PUSH, 3, 0x222, 10.010)]


@pytest.mark.parametrize("legacy", [False, True])
def test_conversation_both_directions(legacy: bool) -> None:
    records = list(decode_frames(conversation(legacy)))
    assert [r["name"] for r in records] == ["speed_control", "get_angles", "speed_control_reply",
                                            "get_angles_reply", "parameter_push"]
    assert [r["direction"] for r in records] == [HOST_TO_GIMBAL] * 2 + [GIMBAL_TO_HOST] * 3
    speed, _, speed_reply, angles, push = records
    assert speed["fields"] == {"yaw_speed": 100, "roll_speed": 0, "pitch_speed": -50, "ctrl_byte": 0x88}
    assert speed["timestamp"] == pytest.approx(10.0003)  # the frame that completed the packet
    assert (speed["seq"], speed["cmd_type"], speed["is_reply"]) == (1, 3, False)
    assert "layout" not in speed and "return_code_meaning" not in speed
    assert speed_reply["layout"] == angles["layout"] == ("legacy" if legacy else "latest")
    assert (speed_reply["cmd_set"], speed_reply["cmd_id"], speed_reply["request_seq"]) == (0x0E, 0x01, 1)
    assert angles["fields"] == {"return_code": 0, "data_type": 1, "yaw": -312, "roll": 4, "pitch": 87}
    assert angles["return_code_meaning"] == "command executed"
    assert push["fields"]["yaw_joint_angle"] == 4 and "layout" not in push
    assert all("error" not in r for r in records)
    json.dumps(records)


def test_legacy_reply_matched_by_seq_not_order() -> None:
    frames = [*frames_of(SpeedControl(), 5, 0x223, 1.0), *frames_of(GetAngles(2), 6, 0x223, 1.001),
              *frames_of(AnglesReply(0, 2, 1, 2, 3), 6, 0x222, 1.002, legacy=True),
              *frames_of(SpeedControlReply(1), 5, 0x222, 1.003, legacy=True)]
    records = list(decode_frames(frames))
    assert [r.get("name") for r in records[2:]] == ["get_angles_reply", "speed_control_reply"]
    assert records[3]["return_code_meaning"] == "command could not be parsed"


def test_legacy_reply_with_fixed_seq_falls_back_to_command_order() -> None:
    # One public driver sends SEQ 1 on every packet: replies then go to the oldest waiting command.
    frames = [*frames_of(GetAngles(1), 1, 0x223, 1.0), *frames_of(SpeedControl(), 1, 0x223, 1.001),
              *frames_of(AnglesReply(0, 1, 1, 2, 3), 1, 0x222, 1.002, legacy=True),
              *frames_of(SpeedControlReply(0), 1, 0x222, 1.003, legacy=True)]
    assert [r.get("name") for r in decode_frames(frames)][2:] == ["get_angles_reply", "speed_control_reply"]


def test_a_command_sent_with_cmd_type_0_waits_for_no_reply() -> None:
    # CmdType 0x00: no reply wanted, so the legacy reply with the same (fixed) SEQ is get-angles'.
    frames = [*frames_of(SpeedControl(), 1, 0x223, 1.0, cmd_type=0x00),
              *frames_of(GetAngles(1), 1, 0x223, 1.001),
              *frames_of(AnglesReply(0, 1, 32, 48, 64), 1, 0x222, 1.002, legacy=True)]
    reply = list(decode_frames(frames))[2]
    assert reply["name"] == "get_angles_reply" and reply["request_seq"] == 1
    assert (reply["fields"]["yaw"], reply["fields"]["roll"], reply["fields"]["pitch"]) == (32, 48, 64)


def test_legacy_reply_with_unechoed_seq_takes_oldest_command() -> None:
    frames = [*frames_of(GetAngles(1), 40, 0x223, 1.0),
              *frames_of(AnglesReply(0, 1, 1, 2, 3), 0, 0x222, 1.002, legacy=True)]
    assert list(decode_frames(frames))[1]["request_seq"] == 40


def test_unmatched_and_expired_legacy_replies_are_errors() -> None:
    reply = frames_of(SpeedControlReply(0), 1, 0x222, 5.0, legacy=True)
    record = list(decode_frames(reply))[0]
    assert record["error"] == "unmatched_legacy_reply" and record["hex"].startswith("aa 11 00 20")
    stale = [*frames_of(SpeedControl(), 1, 0x223, 1.0),
             *frames_of(SpeedControlReply(0), 1, 0x222, 1.0 + REPLY_WINDOW + 0.1, legacy=True)]
    assert list(decode_frames(stale))[1]["error"] == "unmatched_legacy_reply"


@pytest.mark.parametrize("legacy", [False, True], ids=["latest", "legacy"])
def test_a_focus_reply_goes_to_the_command_of_its_sub_id(legacy: bool) -> None:
    """Section 2.3.4.19: a focus motor reply's sub-ID is "与命令帧数据一致" (the same as the
    command's). With a fixed reply SEQ, the calibration reply belongs to the calibration command
    even though the position query (same CmdSet/CmdID) waits longer."""
    frames = [*frames_of(FocusPositionQuery(), 1, 0x223, 1.0), *frames_of(FocusCalibration(), 2, 0x223, 1.001),
              *frames_of(FocusCalibrationReply(0, 0x02, 0x00, 0x00), 0x99, 0x222, 1.002, legacy),
              *frames_of(FocusPositionReply(0, 0x15, 0x00, 0x03, 4000), 0x99, 0x222, 1.003, legacy)]
    replies = list(decode_frames(frames))[2:]
    assert [(r.get("name"), r.get("request_seq")) for r in replies] == \
        [("focus_calibration_reply", 2), ("focus_position_reply", 1)]


def test_a_reply_answers_one_command_only() -> None:
    frames = [*frames_of(SpeedControl(), 1, 0x223, 1.0),
              *frames_of(SpeedControlReply(0), 1, 0x222, 1.001, legacy=True),
              *frames_of(SpeedControlReply(0), 1, 0x222, 1.002, legacy=True)]
    assert [r.get("error") for r in decode_frames(frames)] == [None, None, "unmatched_legacy_reply"]


def test_a_lost_last_frame_does_not_cost_the_next_packet() -> None:
    # The first packet's 1-byte last frame (0xAA) is lost: the next packet's SOF completes it.
    first = next(raw for seq in range(0x10000) if (raw := encode_packet(
        Packet(cmd_type=0x20, seq=seq, data=bytes.fromhex("0e 04 00 91 37 b3 b3 1e 1e"))))[-1] == 0xAA)
    frames = packet_frames(first, 0x222)[:-1] + frames_of(AnglesReply(0, 1, 32, 48, 64), 7, 0x222, 1.0)
    records = list(decode_frames(frames))
    assert [(r.get("name"), r.get("error")) for r in records] == \
        [("get_angle_limits_reply", None), ("get_angles_reply", None)]


def test_pushes_with_reply_bit_do_not_consume_commands() -> None:
    frames = [*frames_of(GetAngles(1), 3, 0x223, 1.0), *frames_of(PUSH, 3, 0x222, 1.001, cmd_type=0x20),
              *frames_of(AnglesReply(0, 1, 1, 2, 3), 3, 0x222, 1.002, legacy=True)]
    records = list(decode_frames(frames))
    assert records[1]["name"] == "parameter_push" and records[1]["is_reply"]
    assert records[2]["name"] == "get_angles_reply"


def test_drops_and_undecodable_packets_become_error_records() -> None:
    good = encode_packet(message_packet(SpeedControl(), 1))
    bad_crc = bytearray(good)
    bad_crc[16] ^= 1
    streams = {
        "garbage": b"\x55\x01\x02",
        "crc32": bytes(bad_crc),
        "encrypted": encode_packet(Packet(0x03, 1, b"\x0e\x01" + bytes(16), enc=0x20)),
        "unknown_command": encode_packet(Packet(0x03, 1, b"\x0e\x42\x00")),
        "bad_payload": encode_packet(Packet(0x03, 1, b"\x0e\x01\x00\x00")),
        "truncated": good[:20],
    }
    for reason, raw in streams.items():
        decoder = LogDecoder()
        records = decoder.feed_bytes(raw, HOST_TO_GIMBAL) + decoder.finish()
        assert [r["error"] for r in records] == [reason], reason
        assert records[0]["hex"] == raw.hex(" ") and records[0]["detail"]


def test_out_of_range_values_are_decoded_and_flagged() -> None:
    raw = encode_packet(Packet(0x03, 1, b"\x0e\x01\x00\x00\x00\x00\x2c\x01\x44"))  # ctrl_byte 0x44
    record = LogDecoder().feed_bytes(raw)[0]
    assert record["fields"]["ctrl_byte"] == 0x44 and "ctrl_byte" in record["out_of_range"]


def test_foreign_ids_and_custom_ids() -> None:
    noise = [can.Message(arbitration_id=0x530, data=b"\x55\xaa\x00"),
             can.Message(arbitration_id=0x222, data=b"\xaa", is_extended_id=True),
             can.Message(arbitration_id=0x222, is_error_frame=True)]
    decoder = LogDecoder()
    assert [r for f in noise for r in decoder.feed_frame(f)] == [] and decoder.foreign_frames == 3
    moved = [can.Message(arbitration_id=0x300 if f.arbitration_id == 0x223 else 0x301, data=f.data,
                         is_extended_id=False, timestamp=f.timestamp) for f in conversation()]
    assert len([r for r in decode_frames(moved, tx_id=0x300, rx_id=0x301) if "error" not in r]) == 5
    assert list(decode_frames(moved)) == []


def test_direction_inferred_from_bytes() -> None:
    stream = b"".join(encode_packet(message_packet(m, 1)) for m in (SpeedControl(), SpeedControlReply(0), PUSH))
    records = LogDecoder().feed_bytes(stream)
    assert [r["direction"] for r in records] == [HOST_TO_GIMBAL, GIMBAL_TO_HOST, GIMBAL_TO_HOST]
    with pytest.raises(ValueError):
        LogDecoder().feed_bytes(b"", "sideways")


@settings(max_examples=200)
@given(st.lists(st.tuples(st.sampled_from([0x222, 0x223, 0x530]), st.binary(max_size=8)), max_size=40))
def test_random_frames_never_raise(frames: list[tuple[int, bytes]]) -> None:
    messages = [can.Message(arbitration_id=i, data=d, is_extended_id=False) for i, d in frames]
    for record in decode_frames(messages):
        json.dumps(record)
        assert "error" in record or "name" in record


@pytest.mark.parametrize("suffix", [".log", ".asc", ".csv", ".blf", ".trc"])
def test_every_log_format_decodes_the_same(tmp_path: Path, suffix: str) -> None:
    path = tmp_path / f"capture{suffix}"
    with can.Logger(str(path)) as writer:
        for frame in conversation(legacy=True):
            frame.channel = 0 if suffix in (".blf", ".asc") else "can0"
            writer.on_message_received(frame)
    records = list(decode_log_file(str(path)))
    assert [r.get("name") for r in records] == ["speed_control", "get_angles", "speed_control_reply",
                                                "get_angles_reply", "parameter_push"]
    assert records[3]["fields"]["yaw"] == -312
