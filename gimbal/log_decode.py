"""CAN traffic (both directions) -> one JSON-ready record per DJI R SDK packet or drop.

Records carry document field names with raw wire values; a value the document does not allow
(e.g. a speed ctrl_byte of 0x44) is decoded as sent and flagged in ``out_of_range``.

``LogDecoder`` is the incremental API (``feed_frame`` / ``feed_bytes`` / ``finish``);
``decode_frames`` and ``decode_log_file`` wrap it for whole captures. Nothing here raises on bad
input: whatever cannot be decoded becomes a record with an ``error`` key and the raw ``hex``.

A record's ``timestamp`` is the time of the frame that completed the packet (or decided the drop).
"""
from __future__ import annotations

from collections import deque
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import Any

import can

from gimbal.errors import PayloadError, RangeError, UnknownMessageError, describe_return_code
from gimbal.framer import Dropped, PacketFramer
from gimbal.messages import (Kind, Message, decode_message, is_device_push, is_legacy_reply,
                             reply_fits)
from gimbal.messages.firmware import (LEGACY_ORDER_DOCUMENT, MISSING_FIELD, check_legacy_order,
                                      empty_get_request)
from gimbal.packet import NO_REPLY, Packet, encode_packet
from gimbal.transport import HOST_RX_ID, HOST_TX_ID

HOST_TO_GIMBAL = "host->gimbal"
GIMBAL_TO_HOST = "gimbal->host"
DIRECTIONS = (HOST_TO_GIMBAL, GIMBAL_TO_HOST)
MAX_OUTSTANDING = 64  # commands remembered for reply matching; the oldest are forgotten first
REPLY_WINDOW = 2.0  # seconds a command may wait for its reply (when timestamps are known)

Record = dict[str, Any]


@dataclass(frozen=True, slots=True)
class _Outstanding:
    """A command seen going to the gimbal, waiting for its reply."""

    seq: int
    message: Message
    timestamp: float | None


def infer_direction(packet: Packet) -> str:
    """Direction of a packet seen without its CAN id: replies and the gimbal's own pushes come
    from the gimbal, everything else from the host."""
    if packet.is_reply or is_device_push(packet):
        return GIMBAL_TO_HOST
    return HOST_TO_GIMBAL


class LogDecoder:
    """Reassembles and decodes both directions of a DJI R SDK conversation.

    Frames on ``tx_id`` are host -> gimbal, frames on ``rx_id`` gimbal -> host, other ids are
    counted in ``foreign_frames`` and ignored. Legacy-layout replies (no CmdSet/CmdID) are
    resolved against the commands seen in the other direction: same SEQ first, else the oldest
    command still waiting. A command sent with CmdType policy 0 (no reply wanted) never waits.
    ``legacy_attitude_order`` is the axis order of legacy angle replies (``gimbal.messages.firmware``).
    """

    def __init__(self, tx_id: int = HOST_TX_ID, rx_id: int = HOST_RX_ID,
                 legacy_attitude_order: str = LEGACY_ORDER_DOCUMENT) -> None:
        self.tx_id = tx_id
        self.rx_id = rx_id
        self.legacy_attitude_order = check_legacy_order(legacy_attitude_order)
        self.foreign_frames = 0
        self._framers = {direction: PacketFramer() for direction in (*DIRECTIONS, None)}
        self._outstanding: deque[_Outstanding] = deque(maxlen=MAX_OUTSTANDING)

    def feed_frame(self, frame: can.Message) -> list[Record]:
        """One CAN frame; returns the records it completed."""
        if frame.is_error_frame or frame.is_remote_frame or frame.is_extended_id:
            self.foreign_frames += 1
            return []
        if frame.arbitration_id == self.tx_id:
            direction = HOST_TO_GIMBAL
        elif frame.arbitration_id == self.rx_id:
            direction = GIMBAL_TO_HOST
        else:
            self.foreign_frames += 1
            return []
        items = self._framers[direction].feed_frame(bytes(frame.data))
        return [self._record(item, direction, frame.timestamp) for item in items]

    def feed_bytes(self, data: bytes, direction: str | None = None,
                   timestamp: float | None = None) -> list[Record]:
        """Raw stream bytes; ``direction`` None infers it per packet (see ``infer_direction``).
        Feed a direction either frames or bytes, not both."""
        if direction not in (*DIRECTIONS, None):
            raise ValueError(f"direction must be one of {DIRECTIONS} or None, not {direction!r}")
        return [self._record(item, direction, timestamp) for item in self._framers[direction].feed(data)]

    def finish(self, timestamp: float | None = None) -> list[Record]:
        """End of input: report the bytes still waiting for the rest of a packet as truncated."""
        return [self._record(drop, direction, timestamp)
                for direction, framer in self._framers.items() for drop in framer.flush()]

    def _record(self, item: Packet | Dropped, direction: str | None, timestamp: float | None) -> Record:
        if isinstance(item, Dropped):
            return {"direction": direction, "timestamp": timestamp, "error": item.reason,
                    "detail": _DROP_DETAILS.get(item.reason, item.reason), "hex": item.data.hex(" ")}
        return self._packet_record(item, direction or infer_direction(item), timestamp)

    def _packet_record(self, packet: Packet, direction: str, timestamp: float | None) -> Record:
        legacy = is_legacy_reply(packet)
        record: Record = {"direction": direction, "timestamp": timestamp, "seq": packet.seq,
                          "cmd_type": packet.cmd_type, "is_reply": packet.is_reply,
                          "cmd_set": None if legacy else _byte(packet.data, 0),
                          "cmd_id": None if legacy else _byte(packet.data, 1)}
        match = self._take_request(packet, legacy, timestamp) if direction == GIMBAL_TO_HOST \
            and packet.is_reply else None
        request = None if match is None else match.message
        if legacy and request is not None:
            record["cmd_set"], record["cmd_id"] = request.CMD_SET, request.CMD_ID
        if direction == HOST_TO_GIMBAL and not packet.is_reply and len(packet.data) >= 2 \
                and (empty := empty_get_request(packet.cmd_set, packet.cmd_id, packet.payload)) is not None:
            return self._empty_get_record(record, packet, empty, timestamp)
        try:
            message = decode_message(packet, request, self.legacy_attitude_order)
        except UnknownMessageError as exc:
            reason = "unmatched_legacy_reply" if legacy and request is None else "unknown_command"
            return {**record, "error": reason, "detail": str(exc), "hex": _hex(packet)}
        except PayloadError as exc:
            return {**record, "error": "bad_payload", "detail": str(exc), "hex": _hex(packet)}
        record.update(name=message.NAME, kind=message.KIND.value, fields=message.fields())
        if message.KIND is Kind.REPLY:
            record["layout"] = "legacy" if legacy else "latest"
            if match is not None:
                record["request_seq"] = match.seq
        try:
            message.validate()
        except RangeError as exc:  # decoded as sent, but outside what the document allows
            record["out_of_range"] = str(exc)
        code = getattr(message, "return_code", None)
        if code is not None:
            record["return_code_meaning"] = describe_return_code(code)
        if direction == HOST_TO_GIMBAL and message.KIND is Kind.COMMAND and message.REPLY is not None \
                and packet.reply_policy != NO_REPLY:
            self._outstanding.append(_Outstanding(packet.seq, message, timestamp))
        record["hex"] = _hex(packet)
        return record

    def _empty_get_record(self, record: Record, packet: Packet, request: type[Message],
                          timestamp: float | None) -> Record:
        """A get request sent without its payload, as some public drivers send them: named, and
        waiting for its reply, but marked as outside the document rather than as damaged."""
        if packet.reply_policy != NO_REPLY:
            self._outstanding.append(_Outstanding(packet.seq, request(), timestamp))
        return {**record, "name": request.NAME, "kind": Kind.COMMAND.value, "fields": {},
                "outside_document": f"{request.NAME} without its payload (the document defines "
                                    f"{MISSING_FIELD[request]}); some public drivers send it so",
                "hex": _hex(packet)}

    def _take_request(self, packet: Packet, legacy: bool, timestamp: float | None) -> _Outstanding | None:
        """Remove and return the outstanding command a reply answers, if any was seen."""
        self._expire(timestamp)
        key = None if legacy else (_byte(packet.data, 0), _byte(packet.data, 1))

        def answers(entry: _Outstanding) -> bool:
            request = entry.message
            return (key is None or (request.CMD_SET, request.CMD_ID) == key) \
                and reply_fits(request, packet)  # a focus sub-ID, a version device ID

        candidates = [e for e in self._outstanding if answers(e)]
        match = next((e for e in candidates if e.seq == packet.seq), None) or \
            (candidates[0] if candidates else None)
        if match is None:
            return None
        self._outstanding.remove(match)
        return match

    def _expire(self, now: float | None) -> None:
        while self._outstanding and now is not None and self._outstanding[0].timestamp is not None \
                and now - self._outstanding[0].timestamp > REPLY_WINDOW:
            self._outstanding.popleft()


_DROP_DETAILS = {
    "garbage": "bytes before a packet start (0xAA)",
    "length": "declared length shorter than any packet",
    "crc16": "header CRC16 mismatch",
    "crc32": "packet CRC32 mismatch",
    "truncated": "packet cut short (the next packet or the end of input came first)",
    "encrypted": "encrypted packet (ENC != 0): the document specifies no key",
    "overflow": "receive buffer overflow",
}


def _byte(data: bytes, index: int) -> int | None:
    return data[index] if len(data) > index else None


def _hex(packet: Packet) -> str:
    return (packet.raw or encode_packet(packet)).hex(" ")


def decode_frames(frames: Iterable[can.Message], tx_id: int = HOST_TX_ID, rx_id: int = HOST_RX_ID,
                  legacy_attitude_order: str = LEGACY_ORDER_DOCUMENT) -> Iterator[Record]:
    """Records for a whole sequence of frames, ending with whatever was left truncated."""
    decoder = LogDecoder(tx_id, rx_id, legacy_attitude_order)
    last = None
    for frame in frames:
        last = frame.timestamp
        yield from decoder.feed_frame(frame)
    yield from decoder.finish(last)


def decode_log_file(path: str, tx_id: int = HOST_TX_ID, rx_id: int = HOST_RX_ID,
                    legacy_attitude_order: str = LEGACY_ORDER_DOCUMENT) -> Iterator[Record]:
    """Records for a CAN log in any format ``can.LogReader`` reads (.log, .asc, .blf, .csv, .trc,
    ...). Opening raises ``OSError``/``ValueError`` for a missing file or unknown format; reading
    errors of a corrupt file propagate from python-can."""
    return decode_frames(can.LogReader(path), tx_id, rx_id, legacy_attitude_order)
