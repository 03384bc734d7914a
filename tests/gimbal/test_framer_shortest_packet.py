"""The shortest packet the framer must recognise: 17 bytes, a legacy-layout reply carrying only its
return code (12-byte header, 1 DATA byte, CRC32), e.g. a NACK from older firmware."""
from __future__ import annotations

from gimbal.framer import Dropped, PacketFramer
from gimbal.messages import message_packet
from gimbal.messages.motion import SpeedControlReply
from gimbal.messages.telemetry import ParameterPush
from gimbal.packet import MIN_PACKET_LEN, decode_packet, encode_packet

NACK = encode_packet(message_packet(SpeedControlReply(return_code=0x02), 9, legacy=True))
PUSH = encode_packet(message_packet(ParameterPush(7, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15), 4))


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
