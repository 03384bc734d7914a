"""Packets <-> 8-byte classic CAN frames on the configured ids, over any python-can bus."""
from __future__ import annotations

import threading
import time
import weakref
from collections import deque
from typing import Any

import can

from gimbal.framer import Dropped, PacketFramer
from gimbal.packet import Packet, encode_packet

HOST_TX_ID = 0x223  # the host sends here; the gimbal listens here
HOST_RX_ID = 0x222  # the gimbal answers here
CAN_FRAME_DATA = 8
DEFAULT_BITRATE = 1_000_000  # the document's 波特率 1M (Figures 37 and 38)

_BUS_LOCKS: weakref.WeakKeyDictionary[can.BusABC, threading.Lock] = weakref.WeakKeyDictionary()
_BUS_LOCKS_GUARD = threading.Lock()


def bus_send_lock(bus: can.BusABC) -> threading.Lock:
    """The one lock every transport on ``bus`` holds while it sends a packet's frames, so two
    transports (e.g. a client and a keep-alive) sharing a bus object never interleave."""
    with _BUS_LOCKS_GUARD:
        lock = _BUS_LOCKS.get(bus)
        if lock is None:
            lock = _BUS_LOCKS[bus] = threading.Lock()
        return lock


def with_default_bitrate(options: dict[str, Any]) -> dict[str, Any]:
    """``can.Bus`` keyword arguments with ``bitrate=DEFAULT_BITRATE`` added when neither
    ``options`` nor python-can's configuration (``can.util.load_config``: can.rc, ``CAN_BITRATE``,
    ``CAN_CONFIG``, config files) gives a bitrate or bit timing. Interfaces whose bitrate is set
    outside python-can (socketcan: ``ip link``; virtual, udp_multicast) ignore it. Raises what
    ``load_config`` raises (``can.CanInterfaceNotImplementedError`` for an unknown interface)."""
    config = options if options.get("ignore_config") else \
        can.util.load_config(config=dict(options), context=options.get("config_context"))
    if config.get("bitrate") is not None or config.get("timing") is not None:
        return dict(options)
    return {**options, "bitrate": DEFAULT_BITRATE}


def packet_frames(raw: bytes, arbitration_id: int) -> list[can.Message]:
    """Cut a packet's bytes into classic CAN frames (the last one shorter)."""
    return [can.Message(arbitration_id=arbitration_id, is_extended_id=False,
                        data=raw[i:i + CAN_FRAME_DATA])
            for i in range(0, len(raw), CAN_FRAME_DATA)]


class CanTransport:
    """Sends packets as frames on ``tx_id`` and reassembles packets from frames on ``rx_id``.

    The host uses the defaults; the device side (the simulator) swaps the two ids. Frames with
    other ids (DJI's accessory traffic, other nodes) are counted and ignored.
    """

    def __init__(self, bus: can.BusABC, tx_id: int = HOST_TX_ID, rx_id: int = HOST_RX_ID,
                 send_timeout: float = 0.05) -> None:
        self.bus = bus
        self.tx_id = tx_id
        self.rx_id = rx_id
        self.send_timeout = send_timeout
        self.framer = PacketFramer()
        self.foreign_frames = 0
        self._send_lock = bus_send_lock(bus)
        self._ready: deque[Packet | Dropped] = deque()

    def send(self, packet: Packet | bytes) -> bytes:
        """Send one packet; its frames go out back to back. Returns the bytes sent.

        Raises ``can.CanError`` when the bus refuses a frame.
        """
        raw = packet if isinstance(packet, bytes) else encode_packet(packet)
        with self._send_lock:
            for frame in packet_frames(raw, self.tx_id):
                self.bus.send(frame, timeout=self.send_timeout)
        return raw

    def recv(self, timeout: float | None = None) -> Packet | Dropped | None:
        """The next packet (or drop report) from ``rx_id``; None when ``timeout`` passes first."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while not self._ready:
            remaining = None if deadline is None else max(0.0, deadline - time.monotonic())
            frame = self.bus.recv(remaining)
            if frame is None:
                return None
            self.feed_frame(frame)
            if deadline is not None and time.monotonic() >= deadline and not self._ready:
                return None
        return self._ready.popleft()

    def feed_frame(self, frame: can.Message) -> None:
        """Take one received frame (for callers that read the bus themselves)."""
        if frame.arbitration_id != self.rx_id or frame.is_extended_id or frame.is_error_frame \
                or frame.is_remote_frame:
            self.foreign_frames += 1
            return
        self._ready.extend(self.framer.feed_frame(bytes(frame.data)))
