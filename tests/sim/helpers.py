"""Test helpers: a raw host (CanTransport + typed messages) and polling."""
from __future__ import annotations

import itertools
import time

import can

from gimbal.messages import Kind, Message, decode_message, message_packet
from gimbal.packet import Packet
from gimbal.transport import CanTransport
from tests.support import wait_until

__all__ = ["RawHost", "wait_until"]  # the sim tests import wait_until from here


class RawHost:
    """Sends commands and waits for the reply with the same SEQ; collects pushes on the way."""

    def __init__(self, bus: can.BusABC) -> None:
        self.transport = CanTransport(bus)
        self.pushes: list[tuple[Message, float]] = []
        self._seq = itertools.count(0x1122)

    def send(self, message: Message, cmd_type: int | None = None) -> int:
        seq = next(self._seq) & 0xFFFF
        self.transport.send(message_packet(message, seq, cmd_type=cmd_type))
        return seq

    def ask(self, message: Message, timeout: float = 0.3, cmd_type: int | None = None) -> Message | None:
        """The decoded reply, or None when none arrives within ``timeout``."""
        packet = self.ask_packet(message, timeout, cmd_type)
        return None if packet is None else decode_message(packet, message)

    def ask_packet(self, message: Message, timeout: float = 0.3, cmd_type: int | None = None) -> Packet | None:
        seq = self.send(message, cmd_type)
        deadline = time.monotonic() + timeout
        while (remaining := deadline - time.monotonic()) > 0:
            packet = self.transport.recv(remaining)
            if isinstance(packet, Packet):
                if packet.is_reply and packet.seq == seq and packet.data[:2] != b"\x0e\x08":
                    return packet
                self._note(packet)
        return None

    def collect(self, seconds: float) -> list[tuple[Message, float]]:
        """Every device push received during ``seconds``."""
        start = len(self.pushes)
        deadline = time.monotonic() + seconds
        while (remaining := deadline - time.monotonic()) > 0:
            packet = self.transport.recv(remaining)
            if isinstance(packet, Packet):
                self._note(packet)
        return self.pushes[start:]

    def _note(self, packet: Packet) -> None:
        try:
            message = decode_message(packet)
        except ValueError:
            return
        if message.KIND is Kind.PUSH:
            self.pushes.append((message, time.monotonic()))

