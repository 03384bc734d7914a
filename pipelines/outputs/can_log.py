"""The session's CAN traffic as a candump-style ``.log`` file (python-can's ``CanutilsLogWriter``).

Each line ends in ``T`` (sent by us) or ``R`` (received), is flushed as it is written, and the file
reads back with ``can.LogReader``, whose messages carry that direction in ``is_rx``.
"""
from __future__ import annotations

import copy
import os
import threading
import time
from typing import Any

import can


class CanLogWriter(can.Listener):
    """A thread-safe ``can.Listener`` writing every message it is given; attach it to a ``can.Notifier``
    or let a ``LoggingBus`` feed it. The direction written is the message's own ``is_rx``; every line
    names ``channel`` (one log holds one bus)."""

    def __init__(self, path: str | os.PathLike[str], channel: str = "can0") -> None:
        self.path = path
        self._file = open(path, "w", encoding="ascii")
        self._writer = can.CanutilsLogWriter(self._file, channel=channel)
        self.channel = channel
        self._lock = threading.Lock()
        self._stopped = False
        self.count = 0

    def on_message_received(self, msg: can.Message) -> None:
        with self._lock:
            if self._stopped:
                return
            line = copy.copy(msg)
            line.channel = self.channel
            self._writer.on_message_received(line)
            self._file.flush()
            self.count += 1

    def stop(self) -> None:
        """Close the file; messages arriving later are ignored."""
        with self._lock:
            if not self._stopped:
                self._stopped = True
                self._writer.stop()


class LoggingBus(can.BusABC):
    """A bus proxy that logs every frame it sends (``T``) and every frame it receives (``R``).

    It owns the wrapped bus and the log: ``shutdown()`` shuts down the one and closes the other.
    Receive filters set on the proxy apply after logging, so the log holds all traffic read.
    """

    def __init__(self, bus: can.BusABC, log: CanLogWriter, **kwargs: Any) -> None:
        self._bus = bus
        self._log = log
        super().__init__(channel=None, **kwargs)
        self._can_protocol = bus.protocol
        self.channel_info = f"logged {bus.channel_info}"

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        self._bus.send(msg, timeout)
        sent = copy.copy(msg)
        sent.is_rx = False
        sent.timestamp = time.time()
        self._log.on_message_received(sent)

    def _recv_internal(self, timeout: float | None) -> tuple[can.Message | None, bool]:
        msg = self._bus.recv(timeout)
        if msg is not None:
            self._log.on_message_received(msg)
        return msg, False

    def shutdown(self) -> None:
        super().shutdown()
        self._bus.shutdown()
        self._log.stop()
