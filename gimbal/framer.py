"""Bytes in any chunking -> whole packets; resyncs on garbage, truncation and CRC failures."""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

from gimbal.crc import crc16, crc32
from gimbal.packet import (HEADER_LEN, MIN_PACKET_LEN, SOF, Packet, PacketError, declared_length,
                           decode_packet)

DEFAULT_MAX_BUFFER = 4 * 1024


@dataclass(frozen=True, slots=True)
class Dropped:
    """Bytes the framer threw away, and why (garbage, length, crc16, crc32, encrypted,
    truncated, overflow)."""

    reason: str
    data: bytes


class PacketFramer:
    """Reassembles packets from a byte stream. ``feed`` never raises on bad input."""

    def __init__(self, max_buffer: int = DEFAULT_MAX_BUFFER) -> None:
        self._buffer = bytearray()
        self._max_buffer = max(max_buffer, 1024)
        self.stats: Counter[str] = Counter()  # "packets" and one key per drop reason (in bytes)

    def feed(self, data: bytes) -> list[Packet | Dropped]:
        """Add bytes; return the packets completed and the drops decided, in stream order."""
        self._buffer += data
        out: list[Packet | Dropped] = []
        while self._step(out):
            pass
        if len(self._buffer) > self._max_buffer:
            out.append(self._drop("overflow", len(self._buffer)))
        return out

    def flush(self) -> list[Dropped]:
        """End of stream: whatever is left is a truncated packet."""
        return [self._drop("truncated", len(self._buffer))] if self._buffer else []

    @property
    def pending(self) -> int:
        """Bytes held waiting for the rest of a packet."""
        return len(self._buffer)

    def _drop(self, reason: str, count: int) -> Dropped:
        dropped = Dropped(reason, bytes(self._buffer[:count]))
        del self._buffer[:count]
        self.stats[reason] += count
        return dropped

    def _step(self, out: list[Packet | Dropped]) -> bool:
        """Consume one packet or one drop from the front of the buffer; False = need more bytes."""
        buf = self._buffer
        if not buf:
            return False
        if buf[0] != SOF:
            start = buf.find(SOF)
            out.append(self._drop("garbage", start if start >= 0 else len(buf)))
            return True
        if len(buf) < 3:
            return False
        length = declared_length(buf)
        if length < MIN_PACKET_LEN:
            out.append(self._drop("length", 1))
            return True
        if len(buf) < HEADER_LEN:
            return False
        if crc16(bytes(buf[:10])) != int.from_bytes(buf[10:12], "little"):
            out.append(self._drop("crc16", 1))
            return True
        if len(buf) < length:
            return False
        raw = bytes(buf[:length])
        if crc32(raw[:-4]) != int.from_bytes(raw[-4:], "little"):
            out.append(self._drop("crc32", 1))  # resync at the next SOF inside this span
            return True
        try:
            packet = decode_packet(raw)
        except PacketError as exc:  # only "encrypted" can remain once both CRCs pass
            out.append(self._drop(exc.reason, length))
            return True
        del buf[:length]
        self.stats["packets"] += 1
        out.append(packet)
        return True
