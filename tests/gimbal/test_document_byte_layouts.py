"""Payload byte layouts written out from the document's tables (sections 2.3.4 and 2.3.5), with a
distinct value in every field: a round trip through our own encoder cannot tell two swapped fields
of the same type apart, these can."""
from __future__ import annotations

import struct

import pytest

from gimbal.messages import Message, decode_message, message_packet
from gimbal.messages.camera import CameraStatusQuery, CameraStatusReply
from gimbal.messages.external import (FocusCalibration, FocusCalibrationReply, FocusPositionQuery,
                                      FocusPositionReply, JoystickPush)
from gimbal.messages.settings import (AngleLimitsReply, GetAngleLimits, GetMotorStiffness,
                                      MotorStiffnessReply, SetAngleLimits, SetMotorStiffness)
from gimbal.messages.telemetry import ParameterPush, VersionPush, VersionQuery, VersionReply
from gimbal.packet import Packet

# (message, its payload per the document's table)
COMMAND_PAYLOADS: list[tuple[Message, bytes]] = [
    # 2.3.4.4 Figure 10: ctrl_byte, pitch_max, pitch_min, yaw_max, yaw_min, roll_max, roll_min.
    (SetAngleLimits(ctrl_byte=1, pitch_max=140, pitch_min=50, yaw_max=170, yaw_min=160,
                    roll_max=25, roll_min=20), bytes((1, 140, 50, 170, 160, 25, 20))),
    # 2.3.4.6 Figure 12: ctrl_byte, pitch, roll, yaw stiffness.
    (SetMotorStiffness(ctrl_byte=1, pitch_stiffness=11, roll_stiffness=22, yaw_stiffness=33), bytes((1, 11, 22, 33))),
    # 2.3.4.10 Figure 17: device id (u32), then version (u32).
    (VersionPush(device_id=2, version=0x01020304), struct.pack("<II", 2, 0x01020304)),
    # 2.3.4.11 Figure 21: device_type, pitch_speed, roll_speed, yaw_speed (int16).
    (JoystickPush(device_type=1, pitch_speed=-300, roll_speed=200, yaw_speed=100), struct.pack("<Bhhh", 1, -300, 200, 100)),
]

# (the command, its reply, the reply payload per the document's table)
REPLY_PAYLOADS: list[tuple[type[Message], Message, bytes]] = [
    # 2.3.4.5 Figure 11: return code, pitch_max, pitch_min, yaw_max, yaw_min, roll_max, roll_min.
    (GetAngleLimits, AngleLimitsReply(return_code=0, pitch_max=140, pitch_min=50, yaw_max=170, yaw_min=160,
                                     roll_max=25, roll_min=20), bytes((0, 140, 50, 170, 160, 25, 20))),
    # 2.3.4.7 Figure 13: return code, pitch, yaw, roll stiffness (not the set command's order).
    (GetMotorStiffness, MotorStiffnessReply(return_code=0, pitch_stiffness=11, yaw_stiffness=33, roll_stiffness=22),
     bytes((0, 11, 33, 22))),
    # 2.3.4.10 Figure 16: return code, device id (u32), version (u32).
    (VersionQuery, VersionReply(return_code=0, device_id=1, version=0x02030405), struct.pack("<BII", 0, 1, 0x02030405)),
    # 2.3.4.19 Figure 33: return code, sub-ID 0x02, motor type 0x00, result.
    (FocusCalibration, FocusCalibrationReply(return_code=0, sub_id=0x02, motor_type=0x00, result=0x01), bytes((0, 0x02, 0x00, 0x01))),
    # 2.3.4.19 Figure 34: return code, sub-ID 0x15, motor type, calibration state, position (u32).
    (FocusPositionQuery, FocusPositionReply(return_code=0, sub_id=0x15, motor_type=0x00, calibration_state=0x03,
                                           position=4000), struct.pack("<BBBBI", 0, 0x15, 0, 3, 4000)),
    # 2.3.5.2 Figure 36: return code, camera status.
    (CameraStatusQuery, CameraStatusReply(return_code=0, camera_status=0x02), bytes((0, 0x02))),
]


@pytest.mark.parametrize("message,payload", COMMAND_PAYLOADS, ids=lambda v: getattr(v, "NAME", ""))
def test_command_payloads_follow_the_documents_tables(message: Message, payload: bytes) -> None:
    """Encoding puts every field at the document's offset, and decoding reads it back from there."""
    assert message.encode_payload() == payload
    packet = Packet.command(message.CMD_SET, message.CMD_ID, payload, seq=1, cmd_type=0x00)
    assert decode_message(packet).fields() == message.fields()


@pytest.mark.parametrize("legacy", [False, True], ids=["latest", "legacy"])
@pytest.mark.parametrize("request_cls,reply,payload", REPLY_PAYLOADS, ids=lambda v: getattr(v, "NAME", ""))
def test_reply_payloads_follow_the_documents_tables(request_cls: type[Message], reply: Message,
                                                    payload: bytes, legacy: bool) -> None:
    """A reply built byte by byte from the document decodes field by field, in both layouts, and
    encodes back to the same bytes."""
    packet = Packet.reply(request_cls.CMD_SET, request_cls.CMD_ID, payload, seq=1, legacy=legacy)
    assert decode_message(packet, request_cls).fields() == reply.fields()
    assert message_packet(reply, 1, legacy=legacy).data == packet.data


def test_parameter_push_stiffness_is_pitch_yaw_roll_at_bytes_19_to_21() -> None:
    """Section 2.3.4.9, Figure 15: the push ends with pitch (19), yaw (20), roll (21) stiffness,
    after the limits in pitch, yaw, roll order (13..18)."""
    payload = struct.pack("<BhhhhhhBBBBBBBBB", 7, 1, 2, 3, 4, 5, 6, 140, 50, 170, 160, 25, 20, 11, 33, 22)
    push = decode_message(Packet.command(0x0E, 0x08, payload, seq=1, cmd_type=0x00))
    assert isinstance(push, ParameterPush)
    assert (push.pitch_max, push.pitch_min, push.yaw_max, push.yaw_min, push.roll_max, push.roll_min) \
        == (140, 50, 170, 160, 25, 20)
    assert (push.pitch_stiffness, push.yaw_stiffness, push.roll_stiffness) == (11, 33, 22)
