"""The DJI R SDK packet (document section 2.1/2.2): header, SEQ, CRC16, data, CRC32."""
from __future__ import annotations

import struct
from dataclasses import dataclass, field

from gimbal.crc import crc16, crc32

SOF = 0xAA
HEADER_LEN = 12  # SOF, ver/length, CmdType, ENC, RES(3), SEQ(2), CRC16(2)
CRC32_LEN = 4
MIN_PACKET_LEN = HEADER_LEN + 1 + CRC32_LEN  # a legacy reply may carry a return code alone
MAX_PACKET_LEN = 0x3FF  # the length field has 10 bits

CMD_TYPE_REPLY_BIT = 0x20
CMD_TYPE_POLICY_MASK = 0x1F
NO_REPLY = 0x00
REPLY_OPTIONAL = 0x01
REPLY_REQUIRED = 0x03  # what DJI's demo and most hosts send
REPLY_CMD_TYPE = 0x20

_HEADER = struct.Struct("<BHBB3sH")  # SOF, ver/length, CmdType, ENC, RES, SEQ


class PacketError(ValueError):
    """A byte string that is not a valid packet; ``reason`` says why in one word."""

    def __init__(self, reason: str, message: str) -> None:
        super().__init__(message)
        self.reason = reason


@dataclass(frozen=True, slots=True)
class Packet:
    """One packet. ``data`` is the DATA field: CmdSet, CmdID and payload (a legacy reply omits
    CmdSet/CmdID and starts with the return code). ``raw`` holds the bytes it was decoded from
    (empty for packets built here); it takes no part in comparisons."""

    cmd_type: int
    seq: int
    data: bytes
    enc: int = 0
    version: int = 0
    raw: bytes = field(default=b"", compare=False, repr=False)

    @classmethod
    def command(cls, cmd_set: int, cmd_id: int, payload: bytes, seq: int,
                cmd_type: int = REPLY_REQUIRED) -> Packet:
        """A command (or push) packet."""
        return cls(cmd_type=cmd_type, seq=seq, data=bytes((cmd_set, cmd_id)) + payload)

    @classmethod
    def reply(cls, cmd_set: int, cmd_id: int, payload: bytes, seq: int, legacy: bool = False) -> Packet:
        """A reply packet: latest layout repeats CmdSet/CmdID, legacy firmware omits them."""
        data = payload if legacy else bytes((cmd_set, cmd_id)) + payload
        return cls(cmd_type=REPLY_CMD_TYPE, seq=seq, data=data)

    @property
    def is_reply(self) -> bool:
        return bool(self.cmd_type & CMD_TYPE_REPLY_BIT)

    @property
    def reply_policy(self) -> int:
        """0 no reply wanted, 1 reply optional, 2..31 reply required."""
        return self.cmd_type & CMD_TYPE_POLICY_MASK

    @property
    def wants_reply(self) -> bool:
        return not self.is_reply and self.reply_policy >= 2

    @property
    def encryption(self) -> int:
        """ENC bits 7..5: 0 none, 1 AES-256."""
        return self.enc >> 5

    @property
    def cmd_set(self) -> int:
        return self.data[0]

    @property
    def cmd_id(self) -> int:
        return self.data[1]

    @property
    def payload(self) -> bytes:
        return self.data[2:]

    @property
    def length(self) -> int:
        return HEADER_LEN + len(self.data) + CRC32_LEN


def encode_packet(packet: Packet) -> bytes:
    """The packet's bytes on the wire, CRCs included."""
    length = packet.length
    if length > MAX_PACKET_LEN:
        raise PacketError("length", f"packet of {length} bytes exceeds the 10-bit length field")
    if not 0 <= packet.seq <= 0xFFFF:
        raise PacketError("seq", f"SEQ {packet.seq} is outside 0..0xFFFF")
    if not 0 <= packet.version <= 0x3F:
        raise PacketError("version", f"version {packet.version} does not fit the 6-bit field")
    if not packet.data:
        raise PacketError("length", "a packet carries at least one DATA byte")
    head = _HEADER.pack(SOF, (packet.version << 10) | length, packet.cmd_type & 0xFF,
                        packet.enc & 0xFF, b"\x00\x00\x00", packet.seq)
    body = head + crc16(head).to_bytes(2, "little") + packet.data
    return body + crc32(body).to_bytes(4, "little")


def declared_length(header: bytes) -> int:
    """The packet length from the first three bytes (SOF and ver/length)."""
    return (header[1] | (header[2] << 8)) & MAX_PACKET_LEN


def decode_packet(raw: bytes) -> Packet:
    """Parse exactly one packet; raises ``PacketError`` (reason sof, short, length, crc16, crc32,
    encrypted)."""
    if len(raw) < HEADER_LEN:
        raise PacketError("short", f"{len(raw)} bytes is shorter than a packet header")
    if raw[0] != SOF:
        raise PacketError("sof", f"first byte 0x{raw[0]:02X} is not SOF 0xAA")
    length = declared_length(raw)
    if not MIN_PACKET_LEN <= length:
        raise PacketError("length", f"declared length {length} is shorter than any packet")
    if len(raw) != length:
        raise PacketError("length", f"declared length {length} but {len(raw)} bytes given")
    if crc16(raw[:10]) != int.from_bytes(raw[10:12], "little"):
        raise PacketError("crc16", "header CRC16 mismatch")
    if crc32(raw[:-4]) != int.from_bytes(raw[-4:], "little"):
        raise PacketError("crc32", "packet CRC32 mismatch")
    return _parse_verified(raw)


def _parse_verified(raw: bytes) -> Packet:
    """Parse one packet whose SOF, length and both CRCs are known to be good (the framer checked
    them); raises ``PacketError`` "encrypted"."""
    _, ver_len, cmd_type, enc, _, seq = _HEADER.unpack_from(raw)
    if enc >> 5:
        raise PacketError("encrypted", f"encrypted packet (ENC 0x{enc:02X}) is not supported: "
                                       "the document specifies no key")
    raw = bytes(raw)
    return Packet(cmd_type=cmd_type, seq=seq, data=raw[HEADER_LEN:-4], enc=enc, version=ver_len >> 10,
                  raw=raw)
