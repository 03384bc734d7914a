"""What firmware and public drivers do differently from the document, in one place: the field order
of legacy attitude replies, and get requests sent with an empty payload.

Legacy attitude order: the document (2.3.4.3) gives an angle reply's axes as yaw, roll, pitch, and
we follow it in both reply layouts. ArduPilot's DJI RS2 driver reads the legacy layout (no
CmdSet/CmdID, 24 bytes) as yaw, pitch, roll; the document's revision 2.2.0.7 changed the
"three-axis angle information", and which order old firmware sends cannot be told without one.
``LEGACY_ORDER_YPR`` reads (and the simulator writes) legacy angle replies in ArduPilot's order;
latest-layout replies always follow the document.
"""
from __future__ import annotations

from gimbal.messages.base import GIMBAL_CMD_SET, Message
from gimbal.messages.motion import AnglesReply
from gimbal.messages.settings import GetAngleLimits, GetMotorStiffness
from gimbal.messages.tlv_params import GetUserParams

LEGACY_ORDER_DOCUMENT = "document"  # yaw, roll, pitch: the document's order
LEGACY_ORDER_YPR = "ypr"  # yaw, pitch, roll: ArduPilot's reading of legacy replies
LEGACY_ORDERS = (LEGACY_ORDER_DOCUMENT, LEGACY_ORDER_YPR)

_SECOND_AXIS = slice(4, 6)  # return code, data_type, yaw (2 bytes), then the two axes that swap
_THIRD_AXIS = slice(6, 8)

#: Get requests some public drivers send without their payload (the document defines a ctrl_byte,
#: or the parameter ids); those drivers report that some gimbals answer them.
MISSING_FIELD = {GetAngleLimits: "ctrl_byte", GetMotorStiffness: "ctrl_byte", GetUserParams: "read_ids"}
EMPTY_GET_REQUESTS: dict[tuple[int, int], type[Message]] = {(GIMBAL_CMD_SET, cls.CMD_ID): cls for cls in MISSING_FIELD}


def check_legacy_order(order: str) -> str:
    """``order`` if it is one of ``LEGACY_ORDERS``; ``ValueError`` naming them otherwise."""
    if order not in LEGACY_ORDERS:
        raise ValueError(f"legacy attitude order must be one of {', '.join(LEGACY_ORDERS)}, not {order!r}")
    return order


def legacy_angles_payload(payload: bytes, order: str) -> bytes:
    """An angle reply's payload between the document's order and ``order`` (either way: the
    swap is its own inverse). Payloads too short to carry the third axis are left alone."""
    if order == LEGACY_ORDER_DOCUMENT or len(payload) < _THIRD_AXIS.stop:
        return payload
    return payload[:_SECOND_AXIS.start] + payload[_THIRD_AXIS] + payload[_SECOND_AXIS] + payload[_THIRD_AXIS.stop:]


def is_angles_reply_key(key: tuple[int, int]) -> bool:
    return key == (AnglesReply.CMD_SET, AnglesReply.CMD_ID)


def empty_get_request(cmd_set: int, cmd_id: int, payload: bytes) -> type[Message] | None:
    """The get command a packet names when it carries no payload, as some drivers send them;
    None for anything else."""
    return None if payload else EMPTY_GET_REQUESTS.get((cmd_set, cmd_id))
