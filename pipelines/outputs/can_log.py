"""The session's CAN traffic as a candump-style ``.log`` file (python-can's ``CanutilsLogWriter``).

Each line ends in ``T`` (sent by us) or ``R`` (received), is flushed as it is written, and the file
reads back with ``can.LogReader``, whose messages carry that direction in ``is_rx``. The writer is
a ``can.Listener`` on the gimbal client's Notifier (``GimbalClient(..., listeners=[log])``), which
also hands it every frame the client sends, marked ``is_rx=False``.
"""
from __future__ import annotations

import copy
import os
import threading

import can


class CanLogWriter(can.Listener):
    """A thread-safe ``can.Listener`` writing every message it is given, from the Notifier's thread
    and from the threads that send. The direction written is the message's own ``is_rx``; every line
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
