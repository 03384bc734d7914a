"""A scripted gimbal for tests: the device end of a python-can bus that answers chosen commands
with chosen replies (either layout, NACK codes, silence, delays) and records what it received."""
from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from types import TracebackType

import can
from can.interfaces.virtual import VirtualBus

from gimbal.client import SPEED_HOLD, SPEED_RELEASE
from gimbal.framer import Dropped
from gimbal.messages import Message, decode_message, message_packet
from gimbal.messages.motion import SpeedControl
from gimbal.packet import Packet
from gimbal.transport import HOST_RX_ID, HOST_TX_ID, CanTransport
from tests.support import wait_until

ReplyFactory = Callable[[Message], Message | None]


@dataclass
class Rule:
    """How to answer one command class; ``reply`` None means stay silent."""

    reply: Message | ReplyFactory | None
    legacy: bool = False
    delay: float = 0.0
    seq: int | None = None  # answer with this SEQ instead of echoing the request's
    ignore_first: int = 0  # stay silent for the first N requests


@dataclass(frozen=True)
class Received:
    t: float
    packet: Packet
    message: Message | None  # None when the packet did not decode


class ScriptedPeer:
    """Listens on the host's tx id and answers on its rx id, per rule."""

    def __init__(self, bus: can.BusABC, *, tx_id: int = HOST_RX_ID, rx_id: int = HOST_TX_ID) -> None:
        self.bus = bus
        self.transport = CanTransport(bus, tx_id=tx_id, rx_id=rx_id)
        self.received: list[Received] = []
        self._rules: dict[type[Message], Rule] = {}
        self._seen: dict[type[Message], int] = {}
        self._cond = threading.Condition()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="scripted-peer", daemon=True)
        self._thread.start()

    def __enter__(self) -> ScriptedPeer:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)

    def answer(self, cls: type[Message], reply: Message | ReplyFactory | None = None, *,
               legacy: bool = False, delay: float = 0.0, seq: int | None = None,
               ignore_first: int = 0) -> None:
        """Answer ``cls`` commands with ``reply`` (default: its reply class, return code 0)."""
        if reply is None:
            assert cls.REPLY is not None
            reply = cls.REPLY()
        with self._cond:
            self._rules[cls] = Rule(reply, legacy, delay, seq, ignore_first)

    def nack(self, cls: type[Message], code: int, *, legacy: bool = False) -> None:
        """Answer ``cls`` with a reply carrying only ``code``."""
        assert cls.REPLY is not None
        self.answer(cls, cls.REPLY(code), legacy=legacy)

    def silence(self, cls: type[Message]) -> None:
        with self._cond:
            self._rules[cls] = Rule(None)

    def push(self, message: Message, *, cmd_type: int | None = None, seq: int = 0) -> None:
        """Send a device push (or any message) unprompted."""
        self.transport.send(message_packet(message, seq, cmd_type))

    def messages(self, cls: type[Message] | None = None) -> list[Message]:
        """Decoded commands and pushes received so far, optionally of one class."""
        with self._cond:
            return [r.message for r in self.received
                    if r.message is not None and (cls is None or type(r.message) is cls)]

    def wait_for(self, cls: type[Message], count: int = 1, timeout: float = 5.0,
                 where: Callable[[Message], bool] = lambda m: True) -> list[Message]:
        """Block until ``count`` messages of ``cls`` matching ``where`` arrived; fail otherwise."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                found = [m for m in self.messages(cls) if where(m)]
                if len(found) >= count:
                    return found
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise AssertionError(f"only {len(found)} of {count} {cls.__name__} within {timeout} s")
                self._cond.wait(remaining)

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                item = self.transport.recv(0.02)
            except can.CanError:
                return
            if item is None or isinstance(item, Dropped):
                continue
            try:
                message: Message | None = decode_message(item)
            except ValueError:
                message = None
            with self._cond:
                self.received.append(Received(time.monotonic(), item, message))
                self._cond.notify_all()
                rule = self._rules.get(type(message)) if message is not None else None
                count = self._seen[type(message)] = self._seen.get(type(message), 0) + 1
            if message is not None and rule is not None and rule.reply is not None \
                    and count > rule.ignore_first:
                self._respond(item, message, rule)

    def _respond(self, request: Packet, message: Message, rule: Rule) -> None:
        reply = rule.reply(message) if callable(rule.reply) else rule.reply
        if reply is None:
            return
        packet = message_packet(reply, request.seq if rule.seq is None else rule.seq,
                                legacy=rule.legacy)
        if rule.delay:
            threading.Timer(rule.delay, self._safe_send, (packet,)).start()
        else:
            self._safe_send(packet)

    def _safe_send(self, packet: Packet) -> None:
        try:
            self.transport.send(packet)
        except can.CanError:
            pass


def poll(condition: Callable[[], bool], timeout: float = 5.0) -> None:
    """Wait for something the other threads do; fail after a generous timeout."""
    assert wait_until(condition, timeout, step=0.005), "condition not reached"


class FlakyBus(VirtualBus):
    """A virtual bus whose receive (or send) side can be made to fail, as when an adapter is
    unplugged."""

    fail_recv = False
    fail_send = False

    def _recv_internal(self, timeout: float | None) -> tuple[can.Message | None, bool]:
        if self.fail_recv:
            raise can.CanOperationError("adapter gone")
        return super()._recv_internal(timeout)

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        if self.fail_send:
            raise can.CanOperationError("adapter gone")
        super().send(msg, timeout)


def speed_messages(peer: ScriptedPeer) -> list[tuple[int, int, int, int]]:
    """(yaw, roll, pitch, ctrl_byte) of every speed command the peer received."""
    return [(m.yaw_speed, m.roll_speed, m.pitch_speed, m.ctrl_byte)
            for m in peer.messages(SpeedControl)]


# the client's own ctrl bytes, pinned to the protocol's values so the tests still check those
assert (SPEED_HOLD, SPEED_RELEASE) == (0x88, 0x08), "speed ctrl bytes are not the R SDK's 0x88/0x08"
ZERO = (0, 0, 0, SPEED_HOLD)  # zero speed, still in control
RELEASE = (0, 0, 0, SPEED_RELEASE)  # zero speed, control released (bit 7 clear)


def ends_with_stop(sent: list[tuple[int, int, int, int]]) -> bool:
    """Whether the speed commands end with the safety stop: zero in control, then the release,
    each sent once or, unanswered, resent until its time was up (issue #26 item 4)."""
    releases = len(sent) - next((i for i in range(len(sent) - 1, -1, -1) if sent[i] != RELEASE), -1) - 1
    rest = sent[:len(sent) - releases]
    return releases >= 1 and bool(rest) and rest[-1] == ZERO
