"""A ``can.Listener`` that turns the gimbal's frames back into packets, for the readers that share
one ``can.Notifier`` (the reply matcher, the push hub)."""
from __future__ import annotations

import time

import can

from gimbal.framer import Dropped, PacketFramer
from gimbal.packet import Packet
from gimbal.transport import HOST_RX_ID, is_packet_frame


class PacketListener(can.Listener):
    """Reassembles packets from the classic frames on ``rx_id`` (other frames are not its business)
    and hands each to ``on_packet`` with its arrival time (``time.monotonic()``). Called by one
    Notifier thread at a time, as python-can does."""

    def __init__(self, rx_id: int = HOST_RX_ID) -> None:
        self.rx_id = rx_id
        self._framer = PacketFramer()

    def on_message_received(self, msg: can.Message) -> None:
        if not is_packet_frame(msg, self.rx_id):
            return
        for item in self._framer.feed_frame(bytes(msg.data)):
            if isinstance(item, Dropped):
                self.on_dropped(item)
            else:
                self.on_packet(item, time.monotonic())

    def on_packet(self, packet: Packet, t: float) -> None:
        raise NotImplementedError

    def on_dropped(self, dropped: Dropped) -> None:
        """Bytes the framer could not use (noise, a bad CRC); ignored unless a subclass counts them."""
