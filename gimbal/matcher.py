"""Pairing replies with the commands they answer, with no I/O of its own."""
from __future__ import annotations

import threading

from gimbal.messages import Message
from gimbal.packet import Packet


class PendingReply:
    """A command on the bus waiting for its reply; ``raw`` is its packet as sent (and resent)."""

    def __init__(self, request: Message, seq: int, raw: bytes) -> None:
        self.request = request
        self.seq = seq
        self.raw = raw
        self.key = (request.CMD_SET, request.CMD_ID)
        self.packet: Packet | None = None
        self.error: BaseException | None = None
        self._event = threading.Event()

    @property
    def done(self) -> bool:
        return self._event.is_set()

    def wait(self, timeout: float) -> bool:
        """True once a reply (or a bus failure) arrived."""
        return self._event.wait(timeout)

    def resolve(self, packet: Packet) -> None:
        self.packet = packet
        self._event.set()

    def fail(self, error: BaseException) -> None:
        self.error = error
        self._event.set()
