"""The packet layer: the document's example byte for byte, header fields and every refusal."""
from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from gimbal.crc import crc16, crc32
from gimbal.packet import (MAX_PACKET_LEN, MIN_PACKET_LEN, Packet, PacketError, decode_packet,
                           encode_packet)

DOC_EXAMPLE = bytes.fromhex("AA 1A 00 03 00 00 00 00 22 11 A2 42 0E 00 20 00 30 00 40 00 01 14 7B 40 97 BE")
DOC_DATA = bytes.fromhex("0E 00 20 00 30 00 40 00 01 14")


def build(cmd_type: int, seq: int, data: bytes, enc: int = 0, res: bytes = b"\0\0\0") -> bytes:
    """A packet assembled by hand, independently of encode_packet."""
    length = 12 + len(data) + 4
    head = bytes((0xAA, length & 0xFF, length >> 8, cmd_type, enc)) + res + seq.to_bytes(2, "little")
    body = head + crc16(head).to_bytes(2, "little") + data
    return body + crc32(body).to_bytes(4, "little")


def test_document_example_encodes_byte_for_byte() -> None:
    assert encode_packet(Packet.command(0x0E, 0x00, DOC_DATA[2:], seq=0x1122)) == DOC_EXAMPLE


def test_document_example_decodes() -> None:
    packet = decode_packet(DOC_EXAMPLE)
    assert (packet.cmd_type, packet.seq, packet.enc, packet.version) == (0x03, 0x1122, 0, 0)
    assert (packet.cmd_set, packet.cmd_id, packet.payload) == (0x0E, 0x00, DOC_DATA[2:])
    assert not packet.is_reply and packet.wants_reply and packet.length == 26
    assert packet.raw == DOC_EXAMPLE


def test_raw_does_not_affect_equality() -> None:
    assert decode_packet(DOC_EXAMPLE) == Packet.command(0x0E, 0x00, DOC_DATA[2:], seq=0x1122)


@pytest.mark.parametrize("cmd_type,policy,wants", [(0x03, 3, True), (0x02, 2, True), (0x00, 0, False),
                                                   (0x01, 1, False)])
def test_host_cmd_types_decode(cmd_type: int, policy: int, wants: bool) -> None:
    packet = decode_packet(build(cmd_type, 1, DOC_DATA))
    assert packet.cmd_type == cmd_type and packet.reply_policy == policy and packet.wants_reply is wants
    assert packet.seq == 1 and not packet.is_reply


def test_reply_bit() -> None:
    packet = decode_packet(build(0x20, 7, b"\x0e\x00\x00"))
    assert packet.is_reply and not packet.wants_reply and packet.reply_policy == 0


def test_reply_layouts_lengths() -> None:
    assert encode_packet(Packet.reply(0x0E, 0x00, b"\x00", seq=1)).__len__() == 19
    assert encode_packet(Packet.reply(0x0E, 0x00, b"\x00", seq=1, legacy=True)).__len__() == 17
    assert Packet.reply(0x0E, 0x00, b"\x00", seq=1, legacy=True).data == b"\x00"


def test_nonzero_reserved_bytes_are_accepted_and_kept_raw() -> None:
    raw = build(0x03, 5, DOC_DATA, res=b"\x01\x02\x03")
    assert decode_packet(raw).raw == raw


@pytest.mark.parametrize("enc", [0x20, 0x2F, 0xE0])
def test_encrypted_packets_are_refused_not_misparsed(enc: int) -> None:
    with pytest.raises(PacketError) as info:
        decode_packet(build(0x03, 1, DOC_DATA + bytes(6), enc=enc))
    assert info.value.reason == "encrypted"


def test_padding_bits_without_encryption_are_not_encryption() -> None:
    assert decode_packet(build(0x03, 1, DOC_DATA, enc=0x05)).encryption == 0


@pytest.mark.parametrize("raw,reason", [
    (DOC_EXAMPLE[:11], "short"),
    (b"\x55" + DOC_EXAMPLE[1:], "sof"),
    (DOC_EXAMPLE[:-1], "length"),
    (DOC_EXAMPLE + b"\x00", "length"),
    (bytes.fromhex("AA 0C 00") + DOC_EXAMPLE[3:], "length"),
    (DOC_EXAMPLE[:10] + b"\x00\x00" + DOC_EXAMPLE[12:], "crc16"),
    (DOC_EXAMPLE[:-1] + b"\x00", "crc32"),
    (DOC_EXAMPLE[:14] + b"\x21" + DOC_EXAMPLE[15:], "crc32"),
])
def test_refusals_name_their_reason(raw: bytes, reason: str) -> None:
    with pytest.raises(PacketError) as info:
        decode_packet(raw)
    assert info.value.reason == reason


@pytest.mark.parametrize("packet,reason", [
    (Packet(0x03, 0x10000, b"\x0e\x00"), "seq"),
    (Packet(0x03, -1, b"\x0e\x00"), "seq"),
    (Packet(0x03, 1, b"\x0e\x00", version=64), "version"),
    (Packet(0x03, 1, b""), "length"),
    (Packet(0x03, 1, bytes(MAX_PACKET_LEN)), "length"),
])
def test_encode_refusals(packet: Packet, reason: str) -> None:
    with pytest.raises(PacketError) as info:
        encode_packet(packet)
    assert info.value.reason == reason


def test_longest_packet_round_trips() -> None:
    packet = Packet(0x03, 9, bytes(range(256)) * 3 + bytes(MAX_PACKET_LEN - 16 - 768))
    assert decode_packet(encode_packet(packet)) == packet and packet.length == MAX_PACKET_LEN


@given(st.integers(0, 0xFF), st.integers(0, 0xFFFF), st.binary(min_size=MIN_PACKET_LEN - 16, max_size=64),
       st.integers(0, 0x1F), st.integers(0, 63))
def test_round_trip(cmd_type: int, seq: int, data: bytes, padding: int, version: int) -> None:
    packet = Packet(cmd_type, seq, data, enc=padding, version=version)
    assert decode_packet(encode_packet(packet)) == packet


@given(st.binary(max_size=80))
def test_random_bytes_raise_only_packet_error(raw: bytes) -> None:
    try:
        decode_packet(raw)
    except PacketError:
        pass
