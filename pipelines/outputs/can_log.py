"""The session's CAN traffic as a candump-style ``.log`` file (python-can's ``CanutilsLogWriter``).

Each line ends in ``T`` (sent by us) or ``R`` (received), is flushed as it is written, and the file
reads back with ``can.LogReader``, whose messages carry that direction in ``is_rx``.
"""
from __future__ import annotations

import copy
import os
import threading
import time
from collections import deque
from typing import Any

import can


ECHO_WINDOW_S = 0.5  # how long a sent frame may take to come back as an echo


class CanLogWriter(can.Listener):
    """A thread-safe ``can.Listener`` writing every message it is given; attach it to a ``can.Notifier``
    or let a ``LoggingBus`` feed it. The direction written is the message's own ``is_rx``; every line
    names ``channel`` (one log holds one bus). A failed write (a full disk) never raises into the
    sender, whose frames, stop commands included, must still go out: logging stops and ``error``
    holds the failure for the owner to report."""

    def __init__(self, path: str | os.PathLike[str], channel: str = "can0") -> None:
        self.path = path
        self._file = open(path, "w", encoding="ascii")
        self._writer = can.CanutilsLogWriter(self._file, channel=channel)
        self.channel = channel
        self._lock = threading.Lock()
        self._stopped = False
        self.count = 0
        self.error: OSError | None = None

    def on_message_received(self, msg: can.Message) -> None:
        with self._lock:
            if self._stopped:
                return
            line = copy.copy(msg)
            line.channel = self.channel
            try:
                self._writer.on_message_received(line)
                self._file.flush()
            except OSError as exc:
                self.error = exc
                self._close()
                return
            self.count += 1

    def stop(self) -> None:
        """Close the file; messages arriving later are ignored."""
        with self._lock:
            self._close()

    def _close(self) -> None:
        if self._stopped:
            return
        self._stopped = True
        try:
            self._writer.stop()
        except OSError as exc:  # the last flush failed: what reached the disk stays readable
            self.error = self.error or exc


class LoggingBus(can.BusABC):
    """A bus proxy that logs every frame it sends (``T``) and every frame it receives (``R``).

    It owns the wrapped bus and the log: ``shutdown()`` shuts down the one and closes the other.
    Receive filters set on the proxy apply after logging, so the log holds all traffic read.
    Some buses hand a sender its own frames back (python-can's udp_multicast always does, unlike
    real adapters); such echoes of what this proxy sent are dropped, so each frame is seen once.
    """

    def __init__(self, bus: can.BusABC, log: CanLogWriter, **kwargs: Any) -> None:
        self._bus = bus
        self._log = log
        super().__init__(channel=None, **kwargs)
        self._can_protocol = bus.protocol
        self.channel_info = f"logged {bus.channel_info}"
        self._sent: deque[tuple[float, int, bytes]] = deque()  # (expiry, id, data) of possible echoes
        self._sent_lock = threading.Lock()

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        now = time.monotonic()
        entry = (now + ECHO_WINDOW_S, msg.arbitration_id, bytes(msg.data))
        with self._sent_lock:  # before sending: the echo may be read before send() returns
            self._forget_before(now)
            self._sent.append(entry)
        try:
            self._bus.send(msg, timeout)
        except BaseException:
            with self._sent_lock:
                if entry in self._sent:
                    self._sent.remove(entry)
            raise
        sent = copy.copy(msg)
        sent.is_rx = False
        sent.timestamp = time.time()
        self._log.on_message_received(sent)

    def _recv_internal(self, timeout: float | None) -> tuple[can.Message | None, bool]:
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            remaining = None if deadline is None else max(0.0, deadline - time.monotonic())
            msg = self._bus.recv(remaining)
            if msg is None:
                return None, False
            if not self._is_echo(msg):
                self._log.on_message_received(msg)
                return msg, False
            if deadline is not None and time.monotonic() >= deadline:
                return None, False

    def _is_echo(self, msg: can.Message) -> bool:
        """Whether ``msg`` is a frame this proxy sent coming back (consumes the match)."""
        now = time.monotonic()
        data = bytes(msg.data)
        with self._sent_lock:
            self._forget_before(now)
            for i, (_, can_id, sent_data) in enumerate(self._sent):
                if can_id == msg.arbitration_id and sent_data == data:
                    del self._sent[i]
                    return True
        return False

    def _forget_before(self, now: float) -> None:
        while self._sent and self._sent[0][0] < now:
            self._sent.popleft()

    def shutdown(self) -> None:
        super().shutdown()
        self._bus.shutdown()
        self._log.stop()
