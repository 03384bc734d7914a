"""Typed payloads for every command, reply and push of the DJI R SDK document, and the decoder
that turns packets into them."""
from __future__ import annotations

from gimbal.errors import PayloadError, UnknownMessageError
from gimbal.messages.base import (CAMERA_CMD_SET, CMD_SETS, DEVICE_PUSHES, GIMBAL_CMD_SET,
                                  HOST_MESSAGES, REPLIES, Kind, Message, Sender, Tlv,
                                  all_message_classes)
from gimbal.messages.camera import *  # noqa: F401,F403  (registers the classes)
from gimbal.messages.external import *  # noqa: F401,F403
from gimbal.messages.firmware import (LEGACY_ORDER_DOCUMENT, LEGACY_ORDERS, is_angles_reply_key,
                                      legacy_angles_payload)
from gimbal.messages.kinds import Command, DevicePush, HostPush, Reply, ReturnCodeReply
from gimbal.messages.motion import *  # noqa: F401,F403
from gimbal.messages.settings import *  # noqa: F401,F403
from gimbal.messages.telemetry import *  # noqa: F401,F403
from gimbal.messages.tlv_params import *  # noqa: F401,F403
from gimbal.packet import NO_REPLY, REPLY_REQUIRED, Packet


def _pick(candidates: list[type[Message]], payload: bytes, what: str) -> type[Message]:
    if len(candidates) == 1:
        return candidates[0]
    for cls in candidates:
        if cls.matches(payload):
            return cls
    raise UnknownMessageError(f"{what}: no layout in the document matches payload {payload.hex(' ')}")


def is_legacy_reply(packet: Packet) -> bool:
    """Legacy firmware omits CmdSet/CmdID in replies. A return code (0x00/0x01/0x02/0xFF) can
    never be a CmdSet (0x0D/0x0E), so the first data byte tells the layouts apart."""
    return packet.is_reply and (not packet.data or packet.data[0] not in CMD_SETS)


def reply_key(packet: Packet) -> tuple[int, int] | None:
    """The CmdSet/CmdID a latest-layout reply repeats, None for a legacy reply. Raises
    ``PayloadError`` for a latest-layout reply too short to hold both."""
    if is_legacy_reply(packet):
        return None
    if len(packet.data) < 2:
        raise PayloadError(f"reply data {packet.data.hex(' ')} is too short for CmdSet/CmdID")
    return packet.data[0], packet.data[1]


def is_device_push(packet: Packet) -> bool:
    """Whether CmdSet/CmdID name a push the device sends, whatever the reply bit says (some
    firmware sets it on pushes)."""
    data = packet.data
    return len(data) >= 2 and (data[0], data[1]) in DEVICE_PUSHES


def reply_fits(request: type[Message] | Message, packet: Packet) -> bool:
    """Whether the reply ``packet`` (either layout) can answer ``request`` (a command, or its
    class): the focus motor replies (0x0E/0x12) echo the command's sub-ID (section 2.3.4.19:
    与命令帧数据一致, "the same as in the command"); a reply carrying its return code alone, or a
    non-zero one (a NACK need not echo the rest), fits any. A command instance also checks what
    its reply names (``Message.reply_is_mine``: the version query's device ID)."""
    payload = packet.data if is_legacy_reply(packet) else packet.data[2:]
    if len(payload) >= 2 and payload[0] == 0 and not request.REPLY.matches(payload):
        return False
    return isinstance(request, type) or request.reply_is_mine(payload)


def decode_message(packet: Packet, request: type[Message] | Message | None = None,
                   legacy_order: str = LEGACY_ORDER_DOCUMENT) -> Message:
    """The typed message a packet carries.

    Pushes are classified by CmdSet/CmdID whatever the reply bit says (some firmware sets it on
    pushes). A legacy reply needs ``request``, the command it answers (class or instance);
    ``legacy_order`` is the axis order of legacy angle replies (``gimbal.messages.firmware``).
    Raises ``PayloadError`` (or its subclass ``UnknownMessageError``).
    """
    data = packet.data
    key = (data[0], data[1]) if len(data) >= 2 else None
    pushes = DEVICE_PUSHES.get(key) if key is not None else None
    if pushes is not None:  # is_device_push(packet), with the candidates at hand
        return _pick(pushes, data[2:], f"push 0x{key[0]:02X}/0x{key[1]:02X}").decode_payload(data[2:])
    if packet.is_reply:
        return _decode_reply(packet, request, legacy_order)
    candidates = HOST_MESSAGES.get(key) if key is not None else None
    if candidates is None:
        raise UnknownMessageError(f"command {data[:2].hex(' ') or '(empty)'} is not defined by the document")
    return _pick(candidates, data[2:], f"command 0x{key[0]:02X}/0x{key[1]:02X}").decode_payload(data[2:])


def _decode_reply(packet: Packet, request: type[Message] | Message | None, legacy_order: str) -> Message:
    key = reply_key(packet)
    if key is not None:
        payload = packet.data[2:]
    elif request is None:
        raise UnknownMessageError("legacy-layout reply (no CmdSet/CmdID) without the command it answers")
    else:
        key, payload = (request.CMD_SET, request.CMD_ID), packet.data
        if is_angles_reply_key(key):
            payload = legacy_angles_payload(payload, legacy_order)
    expected = getattr(request, "REPLY", None)
    if expected is not None and (expected.CMD_SET, expected.CMD_ID) == key:
        if not reply_fits(request, packet):
            raise PayloadError(f"{expected.NAME}: payload {payload.hex(' ')} answers another command "
                               f"than this {request.NAME} (another sub-ID or device ID)")
        return expected.decode_payload(payload)
    if key not in REPLIES:
        raise UnknownMessageError(f"reply to 0x{key[0]:02X}/0x{key[1]:02X}: the document defines none")
    return _pick(REPLIES[key], payload, f"reply 0x{key[0]:02X}/0x{key[1]:02X}").decode_payload(payload)


def message_packet(message: Message, seq: int, cmd_type: int | None = None,
                   legacy: bool = False, legacy_order: str = LEGACY_ORDER_DOCUMENT) -> Packet:
    """Wrap a message in a packet. Commands want a reply when the document defines one; pushes
    want none, and ``cmd_type`` may set the reply bit on them as some firmware does; ``legacy``
    builds a reply in the old layout, angle replies in ``legacy_order``."""
    payload = message.encode_payload()
    if message.KIND is Kind.REPLY:
        if legacy and is_angles_reply_key((message.CMD_SET, message.CMD_ID)):
            payload = legacy_angles_payload(payload, legacy_order)
        return Packet.reply(message.CMD_SET, message.CMD_ID, payload, seq, legacy=legacy)
    if cmd_type is None:
        cmd_type = REPLY_REQUIRED if message.REPLY is not None else NO_REPLY
    return Packet.command(message.CMD_SET, message.CMD_ID, payload, seq, cmd_type)


__all__ = ["CAMERA_CMD_SET", "GIMBAL_CMD_SET", "LEGACY_ORDERS", "LEGACY_ORDER_DOCUMENT", "Command",
           "DevicePush", "HostPush", "Kind", "Message",
           "PayloadError", "Reply", "ReturnCodeReply", "Sender", "Tlv", "UnknownMessageError",
           "all_message_classes", "decode_message", "is_device_push", "is_legacy_reply", "message_packet",
           "reply_fits", "reply_key"]
