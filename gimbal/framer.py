"""Bytes in any chunking -> whole packets; resyncs on garbage, truncation and CRC failures."""
from __future__ import annotations

from collections import Counter, deque
from dataclasses import dataclass

from gimbal.crc import crc16, crc32
from gimbal.packet import (HEADER_LEN, MIN_PACKET_LEN, SOF, Packet, PacketError, _parse_verified,
                           declared_length)

DEFAULT_MAX_BUFFER = 4 * 1024


@dataclass(frozen=True, slots=True)
class Dropped:
    """Bytes the framer threw away, and why (garbage, length, crc16, crc32, encrypted,
    truncated, overflow)."""

    reason: str
    data: bytes


class PacketFramer:
    """Reassembles packets from a byte stream. ``feed`` never raises on bad input.

    Feed one source either with ``feed`` (a stream in any chunking) or with ``feed_frame`` (whole
    CAN frames, which lets the framer use their boundaries), not both.
    """

    def __init__(self, max_buffer: int = DEFAULT_MAX_BUFFER) -> None:
        self._buffer = bytearray()
        self._base = 0  # stream offset of the buffer's first byte
        self._frame_starts: deque[int] = deque()  # stream offsets of the frames in the buffer
        self._scanned = 1  # offsets 1.._scanned-1 of the buffer cannot start a packet
        self._header_ok = False  # the header at the front of the buffer passed its CRC16
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

    def feed_frame(self, data: bytes) -> list[Packet | Dropped]:
        """Add one CAN frame's bytes; like ``feed``, and packets start at a frame's first byte.

        A packet whose last frame was lost can still pass its CRC32 when the next packet's first
        bytes equal the lost ones (a final byte 0xAA, say). It then ends inside that packet's
        first frame, and those bytes are left to start the next packet instead of being lost
        with it.
        """
        self._frame_starts.append(self._base + len(self._buffer))
        return self.feed(data)

    def flush(self) -> list[Dropped]:
        """End of stream: whatever is left is truncated (one drop per packet start found in it)."""
        out = []
        while self._buffer:
            out.append(self._drop("truncated", self._next_start(1, len(self._buffer)) or len(self._buffer)))
        return out

    @property
    def pending(self) -> int:
        """Bytes held waiting for the rest of a packet."""
        return len(self._buffer)

    def _drop(self, reason: str, count: int) -> Dropped:
        dropped = Dropped(reason, bytes(self._buffer[:count]))
        self._discard(count)
        self.stats[reason] += count
        return dropped

    def _discard(self, count: int) -> None:
        """Remove the first ``count`` bytes of the buffer."""
        del self._buffer[:count]
        self._base += count
        while self._frame_starts and self._frame_starts[0] < self._base:
            self._frame_starts.popleft()
        self._scanned = 1
        self._header_ok = False

    def _packet_end(self, length: int) -> int:
        """How many bytes the valid packet of ``length`` at the front of the buffer takes:
        ``length``, unless it began a frame (``feed_frame``) and ends inside a later frame where
        a packet can start. That frame's leading bytes stood in for the packet's lost last frame,
        and belong to the next packet."""
        buf = self._buffer
        starts = self._frame_starts
        if length == len(buf) or not starts or starts[0] != self._base:
            return length  # ends with the last frame; or fed as a stream, or not frame-aligned
        frame_end = len(buf)
        for start in reversed(starts):
            offset = start - self._base
            if offset < length:  # the frame holding the packet's last byte
                if 0 < offset and length < frame_end and buf[offset] == SOF \
                        and self._header_at(offset) is not False:
                    return offset
                return length
            frame_end = offset
        return length

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
            out.append(self._drop("length", self._next_sof(1)))
            return True
        if len(buf) < HEADER_LEN:
            return False
        if not self._header_ok:
            if crc16(bytes(buf[:10])) != int.from_bytes(buf[10:12], "little"):
                out.append(self._drop("crc16", self._next_sof(1)))
                return True
            self._header_ok = True  # not checked again while the rest of the packet arrives
        if len(buf) < length:
            cut = self._complete_packet_inside(len(buf))
            if cut:  # a whole packet already follows: this one lost its tail
                out.append(self._drop("truncated", cut))
                return True
            return False
        raw = bytes(buf[:length])
        if crc32(raw[:-4]) != int.from_bytes(raw[-4:], "little"):
            cut = self._next_start(1, length)  # a packet starting inside means this one was cut short
            out.append(self._drop("truncated", cut) if cut else self._drop("crc32", length))
            return True
        try:
            packet = _parse_verified(raw)
        except PacketError as exc:  # "encrypted"
            out.append(self._drop(exc.reason, length))
            return True
        self._discard(self._packet_end(length))
        self.stats["packets"] += 1
        out.append(packet)
        return True

    def _next_sof(self, start: int) -> int:
        """Offset of the next SOF at or after ``start``, or the buffer length."""
        found = self._buffer.find(SOF, start)
        return found if found >= 0 else len(self._buffer)

    def _header_at(self, offset: int) -> bool | None:
        """Whether a valid header (length and CRC16) starts at ``offset``; None: not all here yet."""
        buf = self._buffer
        if len(buf) - offset < HEADER_LEN:
            return None
        return declared_length(buf[offset:offset + 3]) >= MIN_PACKET_LEN and \
            crc16(bytes(buf[offset:offset + 10])) == int.from_bytes(buf[offset + 10:offset + 12], "little")

    def _next_start(self, start: int, end: int) -> int:
        """First offset in ``start..end-1`` where a packet may start (valid or incomplete header);
        0 when there is none."""
        offset = self._buffer.find(SOF, start, end)
        while offset >= 0:
            if self._header_at(offset) is not False:
                return offset
            offset = self._buffer.find(SOF, offset + 1, end)
        return 0

    def _complete_packet_inside(self, end: int) -> int:
        """Offset (> 0, < ``end``) of a whole packet with both CRCs valid; 0 when there is none.
        Offsets already proven not to start a packet are not examined again."""
        buf = self._buffer
        settled = True  # every offset before the current one is proven not to start a packet
        offset = buf.find(SOF, self._scanned, end)
        while offset >= 0:
            header = self._header_at(offset)
            if header:
                length = declared_length(buf[offset:offset + 3])
                if offset + length <= len(buf) and crc32(bytes(buf[offset:offset + length - 4])) == \
                        int.from_bytes(buf[offset + length - 4:offset + length], "little"):
                    return offset
            if header is not False:
                settled = False
            elif settled:
                self._scanned = offset + 1
            offset = buf.find(SOF, offset + 1, end)
        if settled:
            self._scanned = end
        return 0
