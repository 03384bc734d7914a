"""Packets <-> 8-byte classic CAN frames on the configured ids, over any python-can bus."""
from __future__ import annotations

import copy
import logging
import threading
import time
import weakref
from collections import deque
from typing import Any

import can
from can.interfaces.udp_multicast import UdpMulticastBus

from gimbal.framer import Dropped, PacketFramer
from gimbal.packet import Packet, encode_packet

log = logging.getLogger(__name__)

HOST_TX_ID = 0x223  # the host sends here; the gimbal listens here
HOST_RX_ID = 0x222  # the gimbal answers here
CAN_FRAME_DATA = 8
DEFAULT_BITRATE = 1_000_000  # the document's 波特率 1M (Figures 37 and 38)
ECHO_WINDOW_S = 0.5  # how long a looped-back frame of ours may take to come back

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


def is_packet_frame(frame: can.Message, arbitration_id: int) -> bool:
    """Whether ``frame`` can carry packet bytes on ``arbitration_id``: a classic data frame with
    that standard id (not an error or remote frame, nor someone else's traffic)."""
    return frame.arbitration_id == arbitration_id and not (
        frame.is_extended_id or frame.is_error_frame or frame.is_remote_frame)


def returns_own_frames(bus: can.BusABC) -> bool:
    """Whether ``bus`` hands our sent frames back itself, marked ``is_rx=False``, as python-can's
    interfaces do when opened with ``receive_own_messages=True``."""
    return bool(getattr(bus, "receive_own_messages", False))


def loops_back_as_received(bus: can.BusABC) -> bool:
    """Whether ``bus`` hands every sent frame back to its sender marked as received: python-can's
    udp_multicast does (IP multicast loopback) though it has no ``receive_own_messages``."""
    return isinstance(bus, UdpMulticastBus)


def packet_frames(raw: bytes, arbitration_id: int) -> list[can.Message]:
    """Cut a packet's bytes into classic CAN frames (the last one shorter)."""
    return [can.Message(arbitration_id=arbitration_id, is_extended_id=False,
                        data=raw[i:i + CAN_FRAME_DATA])
            for i in range(0, len(raw), CAN_FRAME_DATA)]


class CanTransport:
    """Sends packets as frames on ``tx_id`` and reassembles packets from frames on ``rx_id``.

    The host uses the defaults; the device side (the simulator) swaps the two ids. Frames with
    other ids (DJI's accessory traffic, other nodes) are counted and ignored.

    A bus does not give its sender's frames back by default, so listeners that want them (a CAN
    log) subscribe with ``add_sent_listener``: each frame that went out is handed to them as
    python-can would, a copy with ``is_rx=False`` and the time it was sent. A bus that returns
    them itself (``receive_own_messages``) is left to do so; one that loops them back marked as
    received (udp_multicast) has those echoes recognised by ``take_echo``.
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
        self._sent_listeners: list[can.Listener] = []
        self._record_sent = not returns_own_frames(bus)
        self._loops_back = loops_back_as_received(bus)
        self._echoes: deque[tuple[float, int, bytes]] = deque()  # (expiry, id, data) still to come back
        self._echo_lock = threading.Lock()

    def add_sent_listener(self, listener: can.Listener) -> None:
        """Hand ``listener`` every frame this transport sends from now on (``is_rx=False``),
        unless the bus returns them itself."""
        self._sent_listeners.append(listener)

    def send(self, packet: Packet | bytes) -> bytes:
        """Send one packet; its frames go out back to back. Returns the bytes sent.

        Raises ``can.CanError`` when the bus refuses a frame.
        """
        raw = packet if isinstance(packet, bytes) else encode_packet(packet)
        with self._send_lock:
            for frame in packet_frames(raw, self.tx_id):
                if self._loops_back:
                    self._expect_echo(frame)  # before sending: the echo may be read before send returns
                try:
                    self.bus.send(frame, timeout=self.send_timeout)
                except BaseException:
                    self._forget_echo(frame)
                    raise
                self._sent(frame)
        return raw

    def _sent(self, frame: can.Message) -> None:
        if not self._record_sent or not self._sent_listeners:
            return
        sent = copy.copy(frame)
        sent.is_rx = False
        sent.timestamp = time.time()
        for listener in self._sent_listeners:
            try:
                listener.on_message_received(sent)
            except Exception:  # a listener's failure must never keep a packet's other frames (a stop) off the bus
                log.exception("listener %r failed on a sent frame", listener)

    def _expect_echo(self, frame: can.Message) -> None:
        now = time.monotonic()
        with self._echo_lock:
            while self._echoes and self._echoes[0][0] < now:
                self._echoes.popleft()
            self._echoes.append((now + ECHO_WINDOW_S, frame.arbitration_id, bytes(frame.data)))

    def _forget_echo(self, frame: can.Message) -> None:
        """A frame the bus refused will not come back."""
        if not self._loops_back:
            return
        with self._echo_lock:
            for i, (_, can_id, data) in enumerate(reversed(self._echoes)):
                if can_id == frame.arbitration_id and data == bytes(frame.data):
                    del self._echoes[len(self._echoes) - 1 - i]
                    return

    def take_echo(self, frame: can.Message) -> bool:
        """Whether a received ``frame`` is a loopback bus handing back one of ours (each sent frame
        is matched once, within ``ECHO_WINDOW_S``); always False on other buses."""
        if not self._loops_back or not frame.is_rx:
            return False
        now = time.monotonic()
        key = (frame.arbitration_id, bytes(frame.data))
        with self._echo_lock:
            while self._echoes and self._echoes[0][0] < now:
                self._echoes.popleft()
            for i, (_, can_id, data) in enumerate(self._echoes):
                if (can_id, data) == key:
                    del self._echoes[i]
                    return True
        return False

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
        if not is_packet_frame(frame, self.rx_id):
            self.foreign_frames += 1
            return
        self._ready.extend(self.framer.feed_frame(bytes(frame.data)))
