"""A serial CAN adapter speaking SLCAN (the Lawicel ASCII protocol of CANable, CANtact, USBtin and
similar) on a pseudo-terminal, wired to a CAN bus: python-can's ``slcan`` interface opens the
terminal's path as it would ``/dev/ttyACM0``, so the simulated gimbal behind it is reached exactly
as a real one behind a USB adapter.

Commands (each ends with CR; answered CR when done, BEL when refused): ``S0``..``S8`` set the
bitrate (10 kbit/s .. 1 Mbit/s), ``sXXYY`` a BTR register value, ``O`` opens the channel, ``L``
opens it listen-only, ``C`` closes it, ``V``/``v``/``N`` report versions and serial number, ``F``
the status flags, ``Z``/``M``/``m`` (timestamps, acceptance filter) are taken and ignored;
``tIIIL<data>`` / ``TIIIIIIIIL<data>`` send a frame (answered ``z`` / ``Z`` + CR), ``r``/``R`` a
remote frame. Received frames are written as ``tIIIL<data>`` + CR while the channel is open.

Like a real bus, nothing gets through at a bitrate other than the gimbal's (the document's
1 Mbit/s): the channel opens, frames are accepted, and the gimbal hears and says nothing.
"""
from __future__ import annotations

import errno
import os
import select
import termios
import threading
import tty
import uuid
from collections import Counter

import can

BITRATE_COMMANDS = {"S0": 10_000, "S1": 20_000, "S2": 50_000, "S3": 100_000, "S4": 125_000,
                    "S5": 250_000, "S6": 500_000, "S7": 750_000, "S8": 1_000_000}
GIMBAL_BITRATE = 1_000_000  # the document's classic CAN at 1 Mbit/s
OK, ERROR = b"\r", b"\a"
HARDWARE_VERSION = "V1013"  # answered to V: hardware 10, software 13 (two digits each, as python-can reads them)
SERIAL_NUMBER = "NSIM1"
MAX_LINE = 64  # longer than any SLCAN command: a line this long without CR is noise and dropped
POLL_S = 0.05


class SlcanPty:
    """A pseudo-terminal speaking SLCAN, bridged to ``bus`` (the CAN side: the simulated gimbal's
    bus, or anything else). ``path`` is the terminal to give python-can (``-i slcan -c PATH``).

    Use as a context manager or ``start()``/``stop()``. The terminal's own end is kept open, so a
    client may close and reopen the path any number of times. ``stats`` counts frames both ways,
    refused commands and frames lost because nobody read the terminal.
    """

    def __init__(self, bus: can.BusABC) -> None:
        self.bus = bus
        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)  # no CR -> LF translation, no echo, before any client opens it
        os.set_blocking(self._master, False)
        self.path = os.ttyname(self._slave)
        self.bitrate: int | None = None
        self.is_open = False
        self.listen_only = False
        self.stats: Counter[str] = Counter()
        self._lock = threading.Lock()  # the channel state, and one writer on the terminal at a time
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []

    def start(self) -> SlcanPty:
        self._threads = [threading.Thread(target=self._serial_loop, name="slcan-pty-rx", daemon=True),
                         threading.Thread(target=self._bus_loop, name="slcan-pty-tx", daemon=True)]
        for thread in self._threads:
            thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        for thread in self._threads:
            thread.join(timeout=2.0)
        for fd in (self._master, self._slave):
            os.close(fd)

    def __enter__(self) -> SlcanPty:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    @property
    def passes_frames(self) -> bool:
        """Whether frames cross between the terminal and the bus: open, at the gimbal's bitrate."""
        return self.is_open and self.bitrate == GIMBAL_BITRATE

    # --- terminal -> bus ---------------------------------------------------------------------

    def _serial_loop(self) -> None:
        line = bytearray()
        while not self._stop.is_set():
            ready, _, _ = select.select([self._master], [], [], POLL_S)
            if not ready:
                continue
            try:
                chunk = os.read(self._master, 4096)
            except BlockingIOError:
                continue
            except OSError as exc:  # EIO: no client has the terminal open (Linux)
                if exc.errno != errno.EIO:
                    raise
                self._stop.wait(POLL_S)
                continue
            for byte in chunk:
                if byte == 0x0D:
                    self._write(self.command(line.decode("ascii", "replace")))
                    line.clear()
                elif len(line) < MAX_LINE:
                    line.append(byte)
                else:
                    self.stats["overlong_lines"] += 1
                    line.clear()

    def command(self, text: str) -> bytes:
        """Carry out one SLCAN command (without its CR); the answer to write back."""
        with self._lock:
            answer = self._command(text)
        if answer == ERROR:
            self.stats["refused"] += 1
        return answer

    def _command(self, text: str) -> bytes:
        head, rest = text[:1], text[1:]
        if text in BITRATE_COMMANDS or head == "s":
            if self.is_open or (head == "s" and not _is_hex(rest, 4)):
                return ERROR
            self.bitrate = BITRATE_COMMANDS.get(text)  # a BTR value: some other bitrate
            return OK
        if text in ("O", "L"):
            if self.is_open or self.bitrate is None:
                return ERROR
            self.is_open, self.listen_only = True, text == "L"
            termios.tcflush(self._slave, termios.TCIFLUSH)  # frames from an earlier session are stale
            return OK
        if text == "C":
            self.is_open = False
            termios.tcflush(self._slave, termios.TCIFLUSH)
            return OK
        if text in ("", "Z0", "Z1") or head in ("M", "m"):
            return OK
        if text in ("V", "v"):
            return (HARDWARE_VERSION if text == "V" else "v" + HARDWARE_VERSION[1:]).encode() + OK
        if text == "N":
            return SERIAL_NUMBER.encode() + OK
        if text == "F":
            return b"F00" + OK
        if head in ("t", "T", "r", "R"):
            return self._transmit(text)
        return ERROR

    def _transmit(self, text: str) -> bytes:
        frame = _parse_frame(text)
        if frame is None or not self.is_open or self.listen_only:
            return ERROR
        if self.passes_frames:
            try:
                self.bus.send(frame, timeout=POLL_S)
                self.stats["to_bus"] += 1
            except can.CanError:
                return ERROR
        return (b"Z" if frame.is_extended_id else b"z") + OK

    # --- bus -> terminal ---------------------------------------------------------------------

    def _bus_loop(self) -> None:
        while not self._stop.is_set():
            frame = self.bus.recv(POLL_S)
            if frame is None or frame.is_error_frame:
                continue
            with self._lock:
                passes = self.passes_frames
            if passes:
                self._write(_format_frame(frame))
                self.stats["to_serial"] += 1

    def _write(self, data: bytes) -> None:
        """Write to the terminal without ever blocking: what a client does not read is lost, as
        on an adapter whose USB host stopped reading."""
        with self._lock:
            try:
                written = os.write(self._master, data)
            except BlockingIOError:
                written = 0
            except OSError as exc:
                if exc.errno != errno.EIO:
                    raise
                written = 0
        if written < len(data):
            self.stats["lost_unread"] += 1


def _is_hex(text: str, length: int | None = None) -> bool:
    try:
        int(text, 16)
    except ValueError:
        return False
    return length is None or len(text) == length


def _parse_frame(text: str) -> can.Message | None:
    """``tIIIL<data>``, ``TIIIIIIIIL<data>``, ``rIIIL``, ``RIIIIIIIIL`` -> a frame; None if malformed."""
    extended = text[0] in "TR"
    remote = text[0] in "rR"
    id_len = 8 if extended else 3
    ident, dlc_text, data = text[1:1 + id_len], text[1 + id_len:2 + id_len], text[2 + id_len:]
    if not _is_hex(ident, id_len) or not dlc_text.isdigit() or int(dlc_text) > 8:
        return None
    dlc = int(dlc_text)
    arbitration_id = int(ident, 16)
    if arbitration_id > (0x1FFFFFFF if extended else 0x7FF):
        return None
    if remote:
        if data:
            return None
        return can.Message(arbitration_id=arbitration_id, is_extended_id=extended, is_remote_frame=True, dlc=dlc)
    if len(data) != 2 * dlc or (data and not _is_hex(data)):
        return None
    return can.Message(arbitration_id=arbitration_id, is_extended_id=extended, data=bytes.fromhex(data))


def _format_frame(frame: can.Message) -> bytes:
    if frame.is_extended_id:
        head = f"{'R' if frame.is_remote_frame else 'T'}{frame.arbitration_id:08X}{frame.dlc:d}"
    else:
        head = f"{'r' if frame.is_remote_frame else 't'}{frame.arbitration_id:03X}{frame.dlc:d}"
    data = "" if frame.is_remote_frame else bytes(frame.data).hex().upper()
    return (head + data).encode() + OK


def virtual_pair() -> tuple[can.BusABC, can.BusABC]:
    """Two ends of a fresh python-can ``virtual`` channel: the adapter's and the gimbal's."""
    channel = f"gimbaltrack-slcan-{uuid.uuid4().hex}"
    return can.Bus(interface="virtual", channel=channel), can.Bus(interface="virtual", channel=channel)
