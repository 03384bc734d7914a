"""Pairing replies with the commands they answer, with no I/O of its own: a ``can.Listener`` fed
the gimbal's frames by the client's ``can.Notifier`` (or by a test).

Replies are matched to requests by SEQ when the gimbal echoes it, otherwise by CmdSet/CmdID
(latest layout) or to the oldest outstanding request (legacy layout, which has no CmdSet/CmdID).
Once the gimbal has echoed a SEQ, a reply with an unknown SEQ is stale; ``ECHO_EVIDENCE`` replies
in a row that could only be paired by command (a gimbal with a fixed SEQ or its own counter, one
of which matched by chance) switch that back. Before the first echo, a reply to another host on
a shared bus cannot be told from a non-echoing gimbal's and is paired by command; when our own
reply then arrives echoing our SEQ, echoing is learnt (``misattributed_replies``), so that costs
the requests then waiting for that command (usually one), not every later one.

A reply that echoes the SEQ of a request given up on (timed out, cancelled) is late
(``late_replies``, counted among the ``stale_replies``): it shows the gimbal echoes SEQs, marks
that request answered late (``PendingReply.late``) and is never handed to a newer request for the
same command. SEQs of requests given up on are
not handed out again while they are remembered, so such a reply cannot be mistaken either.
A resent request is answered once per copy; the replies after the first are
``duplicate_replies``, expected and dropped. Replies that match no outstanding request (``stale_replies``), or are too short to name the
command they answer (``bad_replies``), are counted and dropped.
"""
from __future__ import annotations

import logging
import threading
from collections import Counter, OrderedDict, deque

from gimbal.errors import PayloadError
from gimbal.framer import Dropped
from gimbal.messages import (
    Message,
    is_device_push,
    message_packet,
    reply_fits,
    reply_key,
)
from gimbal.packet import Packet, encode_packet
from gimbal.packet_listener import PacketListener
from gimbal.transport import HOST_RX_ID

log = logging.getLogger(__name__)

FIRST_SEQ = 0x1122  # DJI's demo starts here
ECHO_EVIDENCE = 3  # replies in a row paired only by command that show the gimbal does not echo SEQs
PAIRED_BY_COMMAND_KEPT = 16  # SEQs of the latest requests paired by command, for a late echo
GIVEN_UP_KEPT = 64  # SEQs of the latest requests given up on, for their late replies
RESENT_KEPT = 64  # SEQs of the latest answered requests that went out more than once


class PendingReply:
    """A command on the bus waiting for its reply; ``raw`` is its packet as sent (and resent)."""

    def __init__(self, request: Message, seq: int, raw: bytes) -> None:
        self.request = request
        self.seq = seq
        self.raw = raw
        self.key = (request.CMD_SET, request.CMD_ID)
        self.packet: Packet | None = None
        self.error: BaseException | None = None
        self.late = False  # answered after it was given up on
        self.sends = 0  # times the packet went out (a resend is answered again)
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

    def answered_by(self, packet: Packet, key: tuple[int, int] | None) -> bool:
        """Whether the reply ``packet`` (its CmdSet/CmdID ``key``, None for the legacy layout)
        can answer this request."""
        return (key is None or self.key == key) and reply_fits(self.request, packet)


class ReplyMatcher(PacketListener):
    """Hands out SEQs, keeps the requests waiting for replies and resolves each with its reply.

    ``stats`` (shared with the client's) counts what was dropped and why. Thread-safe: requests
    come from any thread, frames from the Notifier's.
    """

    def __init__(self, rx_id: int = HOST_RX_ID, stats: Counter[str] | None = None) -> None:
        super().__init__(rx_id)
        self.stats: Counter[str] = Counter() if stats is None else stats
        self.next_seq = FIRST_SEQ
        self.seq_echoed = False  # learnt from a reply that echoes its request's SEQ
        self._unechoed_run = 0  # replies in a row since then that could only be paired by command
        self._lock = threading.Lock()
        self._pending: dict[int, PendingReply] = {}
        self._given_up: OrderedDict[int, PendingReply] = OrderedDict()
        self._resent: OrderedDict[tuple[int, tuple[int, int] | None], int] = OrderedDict()  # replies still due
        self._paired_by_command: deque[tuple[int, tuple[int, int] | None]] = \
            deque(maxlen=PAIRED_BY_COMMAND_KEPT)  # (SEQ, reply key) of requests paired by command

    # -- requests --------------------------------------------------------------------------

    def encode(self, message: Message, cmd_type: int | None = None) -> tuple[int, bytes]:
        """The next free SEQ and the packet bytes of ``message`` with it. Encoding validates: a
        ``RangeError`` leaves the SEQ unused."""
        with self._lock:
            seq = self.next_seq
            while seq in self._pending or seq in self._given_up:
                seq = (seq + 1) & 0xFFFF
            raw = encode_packet(message_packet(message, seq, cmd_type))
            self.next_seq = (seq + 1) & 0xFFFF
            return seq, raw

    def expect(self, waiter: PendingReply) -> None:
        """Wait for ``waiter``'s reply (again, for a retry that was not yet answered)."""
        with self._lock:
            waiter.sends += 1
            self._pending.setdefault(waiter.seq, waiter)

    def cancel(self, waiter: PendingReply) -> None:
        """Stop waiting for ``waiter``'s reply; if none came, a reply arriving later is late."""
        with self._lock:
            if self._pending.get(waiter.seq) is waiter:
                del self._pending[waiter.seq]
            if not waiter.done:
                self._given_up[waiter.seq] = waiter
                self._given_up.move_to_end(waiter.seq)
                while len(self._given_up) > GIVEN_UP_KEPT:
                    self._given_up.popitem(last=False)

    def fail_all(self, error: BaseException) -> None:
        """Fail every waiting request (the bus is lost or the client closed)."""
        with self._lock:
            waiters = list(self._pending.values())
            self._pending.clear()
        for waiter in waiters:
            waiter.fail(error)

    # -- replies ---------------------------------------------------------------------------

    def on_dropped(self, dropped: Dropped) -> None:
        self.stats[f"dropped_{dropped.reason}"] += len(dropped.data)
        log.debug("dropped %d bytes (%s)", len(dropped.data), dropped.reason)

    def on_packet(self, packet: Packet, t: float) -> None:
        if is_device_push(packet):
            return  # the push hub's
        if not packet.is_reply:
            self.stats["ignored"] += 1
            return
        try:
            waiter = self.match(packet)
        except PayloadError as exc:
            self.stats["bad_replies"] += 1
            log.warning("undecodable reply: %s", exc)
            return
        if waiter is None:
            self.stats["stale_replies"] += 1
            log.debug("reply SEQ 0x%04X matches no outstanding request", packet.seq)
        else:
            waiter.resolve(packet)

    def match(self, packet: Packet) -> PendingReply | None:
        """Pop the waiter a reply belongs to, None for a reply to drop (see the module's
        docstring). A focus motor reply (0x12) only answers a request of the sub-command it
        echoes, a version reply (0x09) only the query for the device it names (``reply_fits``).
        Raises ``PayloadError`` for a reply too short to say which command it answers."""
        key = reply_key(packet)
        with self._lock:
            waiter = self._pending.get(packet.seq)
            echoed = waiter is not None and waiter.answered_by(packet, key)
            if not echoed:
                given_up = self._given_up.get(packet.seq)
                if given_up is not None and given_up.answered_by(packet, key):
                    self._late(given_up, packet)
                    self._expect_duplicates(given_up, key)
                    return None
                if self._duplicate(packet.seq, key):
                    return None
                waiter = next((w for w in self._pending.values() if w.answered_by(packet, key)), None)
                if waiter is None and (packet.seq, key) in self._paired_by_command:
                    self._late_echo(packet.seq)
            self._note_echo(echoed, waiter is not None)
            if waiter is not None and not echoed and self.seq_echoed:
                waiter = None
            if waiter is not None:
                del self._pending[waiter.seq]
                if not echoed:
                    self._paired_by_command.append((waiter.seq, key))
                else:
                    self._expect_duplicates(waiter, key)
            return waiter

    def _expect_duplicates(self, waiter: PendingReply, key: tuple[int, int] | None) -> None:
        """An answered request that went out more than once is answered once more for each resend
        (the final stop is resent until answered): those replies are expected (lock held)."""
        if waiter.sends > 1:
            self._resent[(waiter.seq, key)] = waiter.sends - 1
            while len(self._resent) > RESENT_KEPT:
                self._resent.popitem(last=False)

    def _duplicate(self, seq: int, key: tuple[int, int] | None) -> bool:
        """A reply to a resend of a request already answered (``duplicate_replies``): dropped
        without counting as a gimbal that does not echo SEQs (lock held)."""
        due = self._resent.get((seq, key), 0)
        if not due:
            return False
        if due == 1:
            del self._resent[(seq, key)]
        else:
            self._resent[(seq, key)] = due - 1
        self.stats["duplicate_replies"] += 1
        return True

    def _late(self, waiter: PendingReply, packet: Packet) -> None:
        """A reply to a request given up on: it echoes that request's SEQ. The request is marked
        answered late (for whoever still looks, the keep-alive), and handed to nobody (lock held)."""
        self.stats["late_replies"] += 1
        del self._given_up[waiter.seq]
        self._note_echo(True, False)
        waiter.late = True
        waiter.resolve(packet)
        log.debug("late reply to %s (SEQ 0x%04X), dropped", waiter.request.NAME, waiter.seq)

    def _late_echo(self, seq: int) -> None:
        """A reply echoing the SEQ of a request that an earlier reply, paired by command, already
        completed: the gimbal echoes after all, and that earlier reply was someone else's (another
        host's on a shared bus). Replies with unknown SEQs are stale from now on (lock held)."""
        self.stats["misattributed_replies"] += 1
        log.warning("reply SEQ 0x%04X echoes a request already answered by a reply paired by "
                    "command (another host's?): pairing by SEQ only from now on", seq)
        self.seq_echoed, self._unechoed_run = True, 0
        self._paired_by_command.clear()

    def _note_echo(self, echoed: bool, by_command: bool) -> None:
        """A reply that echoed its request's SEQ shows the gimbal echoes; ``ECHO_EVIDENCE`` in a
        row that could only be paired by command show that was chance (a fixed reply SEQ once
        the client's counter wraps to it), and they are paired by command again."""
        if echoed:
            self.seq_echoed, self._unechoed_run = True, 0
        elif by_command:
            self._unechoed_run += 1
            if self._unechoed_run >= ECHO_EVIDENCE:
                self.seq_echoed = False
