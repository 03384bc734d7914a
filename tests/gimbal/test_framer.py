"""The stream framer: any chunking, garbage, truncation and CRC damage, never raising."""
from __future__ import annotations

from hypothesis import given, settings, strategies as st

from gimbal.framer import Dropped, PacketFramer
from gimbal.messages import message_packet
from gimbal.messages.motion import AnglesReply, SpeedControl, SpeedControlReply
from gimbal.messages.telemetry import ParameterPush
from gimbal.packet import MIN_PACKET_LEN, Packet, decode_packet, encode_packet


DOC_EXAMPLE = bytes.fromhex("AA 1A 00 03 00 00 00 00 22 11 A2 42 0E 00 20 00 30 00 40 00 01 14 7B 40 97 BE")
SPEED = encode_packet(message_packet(SpeedControl(100, 0, -20), 2))
REPLY = encode_packet(message_packet(AnglesReply(0, 1, 5, 6, 7), 3))
PUSH = encode_packet(message_packet(ParameterPush(7, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15), 4))
STREAM = DOC_EXAMPLE + SPEED + REPLY + PUSH
PACKETS = [decode_packet(raw) for raw in (DOC_EXAMPLE, SPEED, REPLY, PUSH)]


def feed_all(chunks: list[bytes], framer: PacketFramer | None = None) -> list[Packet | Dropped]:
    framer = framer or PacketFramer()
    return [item for chunk in chunks for item in framer.feed(chunk)] + framer.flush()


def packets(items: list[Packet | Dropped]) -> list[Packet]:
    return [i for i in items if isinstance(i, Packet)]


def drops(items: list[Packet | Dropped]) -> list[tuple[str, bytes]]:
    return [(i.reason, i.data) for i in items if isinstance(i, Dropped)]


def test_whole_stream() -> None:
    assert feed_all([STREAM]) == PACKETS


def test_split_at_every_offset() -> None:
    for cut in range(len(STREAM) + 1):
        assert feed_all([STREAM[:cut], STREAM[cut:]]) == PACKETS, cut


def test_byte_at_a_time() -> None:
    framer = PacketFramer()
    assert feed_all([bytes((b,)) for b in STREAM], framer) == PACKETS
    assert framer.pending == 0 and framer.stats["packets"] == 4


def test_can_frame_chunks() -> None:
    assert feed_all([STREAM[i:i + 8] for i in range(0, len(STREAM), 8)]) == PACKETS


def test_garbage_padding_is_dropped_with_stats() -> None:
    framer = PacketFramer()
    items = feed_all([b"\x55\x01\x02" + DOC_EXAMPLE + b"\x00" * 5 + SPEED + b"\x77"], framer)
    assert packets(items) == PACKETS[:2]
    assert drops(items) == [("garbage", b"\x55\x01\x02"), ("garbage", b"\x00" * 5), ("garbage", b"\x77")]
    assert framer.stats["garbage"] == 9


def test_stray_sof_bytes_resync() -> None:
    items = feed_all([b"\xaa\x01\x00" + b"\xaa" * 20 + DOC_EXAMPLE])
    assert packets(items) == PACKETS[:1]
    assert {reason for reason, _ in drops(items)} <= {"length", "crc16"}


def test_truncated_packet_followed_by_a_packet() -> None:
    items = feed_all([SPEED[:13] + REPLY + PUSH])
    assert packets(items) == PACKETS[2:]
    assert drops(items) == [("truncated", SPEED[:13])]


def test_truncated_packet_is_reported_without_waiting_for_its_length() -> None:
    # A push lost its tail; a short reply follows. The reply must come out at once, not when
    # enough later bytes have arrived to fill the push's declared length.
    framer = PacketFramer()
    items = framer.feed(PUSH[:24] + REPLY)
    assert packets(items) == PACKETS[2:3] and drops(items) == [("truncated", PUSH[:24])]
    assert framer.pending == 0


@given(st.integers(1, len(PUSH) - 1), st.integers(1, 9))
def test_truncated_packet_then_packets_in_any_chunking(cut: int, size: int) -> None:
    stream = PUSH[:cut] + REPLY + SPEED
    items = feed_all([stream[i:i + size] for i in range(0, len(stream), size)])
    assert packets(items) == [PACKETS[2], PACKETS[1]]
    assert b"".join(data for _, data in drops(items)) == PUSH[:cut]


def test_a_lost_last_frame_does_not_cost_the_next_packet() -> None:
    # 25 bytes = frames of 8, 8, 8, 1, the last one holding only the final CRC byte 0xAA. When it is
    # lost, the next packet's SOF completes this one with a valid CRC32: the next packet must
    # still be found, since packets start at a frame's first byte.
    lost_tail = next(raw for seq in range(0x10000) if (raw := encode_packet(
        Packet(cmd_type=0x20, seq=seq, data=bytes.fromhex("0e 04 00 91 37 b3 b3 1e 1e"))))[-1] == 0xAA)
    frames = [lost_tail[i:i + 8] for i in range(0, 24, 8)] + [REPLY[i:i + 8] for i in range(0, len(REPLY), 8)]
    framer = PacketFramer()
    items = [item for frame in frames for item in framer.feed_frame(frame)] + framer.flush()
    assert items == [decode_packet(lost_tail), decode_packet(REPLY)]


def test_frames_cut_across_packets_frame_like_the_stream() -> None:
    # A sender that does not start each packet on a new frame: no harm done.
    framer = PacketFramer()
    items = [item for i in range(0, len(STREAM), 8) for item in framer.feed_frame(STREAM[i:i + 8])]
    assert items + framer.flush() == PACKETS


def test_truncated_at_end_of_stream() -> None:
    framer = PacketFramer()
    assert packets(framer.feed(DOC_EXAMPLE + SPEED[:20])) == PACKETS[:1]
    assert framer.pending == 20
    assert [(d.reason, d.data) for d in framer.flush()] == [("truncated", SPEED[:20])]
    assert framer.pending == 0 and framer.flush() == []


def test_two_truncated_packets_at_end_are_two_drops() -> None:
    assert drops(feed_all([SPEED[:15] + PUSH[:14]])) == [("truncated", SPEED[:15]), ("truncated", PUSH[:14])]
    # Cut inside its header, a packet fails the header CRC: still one drop, then the next packet.
    assert drops(feed_all([SPEED[:5] + PUSH[:14]])) == [("crc16", SPEED[:5]), ("truncated", PUSH[:14])]


def test_corrupted_crc16_resyncs_to_next_packet() -> None:
    bad = bytearray(SPEED)
    bad[8] ^= 0x01  # SEQ byte: header CRC fails
    items = feed_all([bytes(bad) + REPLY])
    assert packets(items) == PACKETS[2:3]
    assert drops(items) == [("crc16", bytes(bad))]


def test_corrupted_crc32_resyncs_to_next_packet() -> None:
    bad = bytearray(PUSH)
    bad[20] ^= 0x40  # payload byte: whole-packet CRC fails
    framer = PacketFramer()
    items = feed_all([bytes(bad) + DOC_EXAMPLE], framer)
    assert packets(items) == PACKETS[:1]
    assert drops(items) == [("crc32", bytes(bad))]
    assert framer.stats["crc32"] == len(PUSH)


def test_encrypted_packet_dropped_whole() -> None:
    encrypted = encode_packet(Packet(0x03, 1, b"\x0e\x01" + bytes(16), enc=0x20 | 9))
    items = feed_all([encrypted + SPEED])
    assert drops(items) == [("encrypted", encrypted)] and packets(items) == PACKETS[1:2]


def test_buffer_stays_bounded() -> None:
    framer = PacketFramer(max_buffer=1024)
    # A valid header declaring the longest packet, then never its body: the framer waits, bounded.
    head = bytearray(encode_packet(Packet(0x03, 1, bytes(1007)))[:12])
    framer.feed(bytes(head))
    for _ in range(200):
        framer.feed(b"\x00" * 64)
        assert framer.pending <= 1024
    assert framer.stats["crc32"] + framer.stats["garbage"] > 0


@settings(max_examples=300)
@given(st.lists(st.binary(max_size=40), max_size=20))
def test_random_garbage_never_raises(chunks: list[bytes]) -> None:
    framer = PacketFramer()
    items = feed_all(chunks, framer)
    dropped = sum(len(i.data) for i in items if isinstance(i, Dropped))
    kept = sum(len(encode_packet(i)) for i in items if isinstance(i, Packet))
    assert dropped + kept == sum(map(len, chunks))  # every byte accounted for exactly once
    assert framer.pending == 0


@settings(max_examples=200)
@given(st.binary(max_size=60), st.binary(max_size=60), st.lists(st.integers(1, 30), max_size=30))
def test_packets_survive_garbage_around_them(before: bytes, after: bytes, cuts: list[int]) -> None:
    stream = before + STREAM + after
    chunks, offset = [], 0
    for size in cuts:
        chunks.append(stream[offset:offset + size])
        offset += size
    chunks.append(stream[offset:])
    # Garbage before the stream may swallow a packet only if it forms a packet header itself,
    # which random bytes essentially never do; the packets after it must all come out.
    assert packets(feed_all(chunks))[-4:] == PACKETS


# The shortest packet the framer must recognise: 17 bytes, a legacy-layout reply carrying only its
# return code (12-byte header, 1 DATA byte, CRC32), e.g. a NACK from older firmware.
NACK = encode_packet(message_packet(SpeedControlReply(return_code=0x02), 9, legacy=True))


def test_a_legacy_nack_is_the_shortest_packet() -> None:
    """Return code alone: 17 bytes on the wire, and a packet of its own."""
    assert len(NACK) == MIN_PACKET_LEN == 17
    assert PacketFramer().feed(NACK) == [decode_packet(NACK)]


def test_a_nack_after_a_truncated_packet_comes_out_at_once() -> None:
    """A push that lost its tail is dropped as soon as the 17-byte reply after it is complete,
    without waiting for bytes enough to fill the push's declared length."""
    framer = PacketFramer()
    items = framer.feed(PUSH[:20] + NACK)
    assert items == [Dropped("truncated", PUSH[:20]), decode_packet(NACK)]
    assert framer.pending == 0
