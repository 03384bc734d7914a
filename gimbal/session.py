"""The core of the host side: the bus, the ``can.Notifier`` that receives for every listener,
requests and their replies, pushes, and the safety stop.

Angles are degrees and speeds °/s in the typed commands (``gimbal.commands``); here messages go
out as they are, range-checked by the codec (``RangeError``) before anything is sent.

One ``can.Notifier`` reads the bus. Its listeners, in order: the bus watch (which thread
receives; passing receive errors against a lost bus), the taps (listeners added with
``listeners=``/``add_listener``, such as a CAN log), the reply matcher (``gimbal.matcher``) and the
push hub (``gimbal.pushes``). A bus does not give back its sender's frames by default, so the taps
also get every frame this client sends, as a copy marked ``is_rx=False`` (``CanTransport``).
A retry resends the *same* packet with the same SEQ, so a late reply to any attempt completes the
call. Commands whose repetition changes the outcome (relative moves, toggles, camera actions)
are never retried.
"""
from __future__ import annotations

import atexit
import logging
import threading
import time
from collections import Counter
from collections.abc import Callable, Iterable
from types import TracebackType
from typing import Any, Self

import can

from gimbal.errors import (
    BusError,
    GimbalError,
    GimbalTimeoutError,
    ReturnCodeError,
    SendError,
)
from gimbal.framer import PacketFramer
from gimbal.keepalive import DEFAULT_MAX_AGE_S, SpeedStreamer
from gimbal.matcher import PendingReply, ReplyMatcher
from gimbal.messages import Message, Reply, decode_message
from gimbal.messages.firmware import LEGACY_ORDER_DOCUMENT, check_legacy_order
from gimbal.messages.motion import (
    SPEED_HOLD,
    SPEED_RELEASE,
    SPEED_TAKE_CONTROL,
    SpeedControl,
)
from gimbal.other_hosts import OtherHosts
from gimbal.packet import REPLY_OPTIONAL
from gimbal.pushes import PushCallback, PushHub
from gimbal.transport import (
    HOST_RX_ID,
    HOST_TX_ID,
    CanTransport,
    is_packet_frame,
    with_default_bitrate,
)
from gimbal.values import integer, number, shown
from gimbal.watchdog import DEFAULT_TIMEOUT_S, BusWatchdog

log = logging.getLogger(__name__)

RX_POLL_S = 0.05  # the Notifier's receive timeout, and the pause after a receive error
RX_GIVE_UP_S = 0.25  # receive errors for this long, without a frame between, mean the bus is lost
STOP_RETRY_S = 0.5  # the final stop is resent until answered or this long has passed
STOP_RESEND_S = 0.05  # between resends of an unanswered stop command
NOTIFIER_STOP_S = 1.0  # how long close() waits for the Notifier's thread
MAX_TIMEOUT = threading.TIMEOUT_MAX  # longer waits overflow the platform's time_t


def stop_messages() -> tuple[SpeedControl, SpeedControl]:
    """The safety stop: zero speed still in control, then zero with control released."""
    return SpeedControl(0, 0, 0, SPEED_HOLD), SpeedControl(0, 0, 0, SPEED_RELEASE)


def _is_stop(message: Message) -> bool:
    return message in stop_messages()


def _checked_wait(timeout: float, retries: int) -> tuple[float, int]:
    """A reply timeout (s, above 0, at most ``MAX_TIMEOUT``) and retry count (an int, 0 or more) as
    float and int; ``ValueError`` naming what is wrong otherwise."""
    if not number(0, MAX_TIMEOUT, above=True)(timeout):
        raise ValueError(f"timeout must be above 0 and at most {MAX_TIMEOUT:.0f} s, not {shown(timeout)}")
    if not integer(0)(retries):
        raise ValueError(f"retries must be a whole number, 0 or more, not {shown(retries)}")
    return float(timeout), int(retries)


class _BusWatch(can.Listener):
    """First on the Notifier: notes the thread that receives (push callbacks run on it) and hands
    errors (the bus's, or a listener's) to the session."""

    def __init__(self, on_error: Callable[[Exception], None]) -> None:
        self.thread: threading.Thread | None = None
        self.failing_since: float | None = None  # monotonic time of the first receive error in a row
        self._on_error = on_error

    def on_message_received(self, msg: can.Message) -> None:
        self.thread = threading.current_thread()
        self.failing_since = None

    def on_error(self, exc: Exception) -> None:
        self.thread = threading.current_thread()
        self._on_error(exc)


class _Taps(can.Listener):
    """The listeners that want every frame as the bus saw it (a CAN log). On a bus that loops our
    own frames back marked as received (udp_multicast) those echoes are left out: the taps got
    each of our frames at send already. Any other frame on our transmit id is another host's and
    also goes to ``other_hosts``. Once the client closes (``close_at_packet_end``) they get
    frames until the gimbal's stream is between two packets, so a log never ends with half of one
    that the client did not read either."""

    def __init__(self, transport: CanTransport, other_hosts: OtherHosts) -> None:
        self.listeners: list[can.Listener] = []
        self.other_hosts = other_hosts
        self._transport = transport
        self._gimbal_stream = PacketFramer()  # where the gimbal's packets start and end
        self._closing = False
        self._closed = False

    def close_at_packet_end(self) -> None:
        self._closing = True

    def on_message_received(self, msg: can.Message) -> None:
        if self._closed or self._transport.take_echo(msg):
            return
        self.other_hosts.on_message_received(msg)
        if not self.listeners:
            return
        if is_packet_frame(msg, self._transport.rx_id):
            if self._closing and not self._gimbal_stream.pending:
                self._closed = True  # this frame would start a packet nobody reads to its end
                return
            self._gimbal_stream.feed_frame(bytes(msg.data))
        for listener in self.listeners:
            listener.on_message_received(msg)

    def stop(self) -> None:
        for listener in self.listeners:
            listener.stop()


class GimbalSession:
    """Talks to one DJI RS gimbal over a python-can bus: lifecycle, requests, pushes, safety stop.

    ``bus`` may be any ``can.BusABC``; without one, ``can.Bus(**bus_kwargs)`` is built from
    python-can's own configuration (``interface=``, ``channel=``, can.rc, ``CAN_*`` variables,
    ``~/.canrc``), at the document's 1 Mbit/s unless a bitrate is given or configured, and shut
    down on close. The client starts a ``can.Notifier`` on the bus (python-can allows one per
    bus); ``listeners`` (and ``add_listener``) share it. Use as a context manager: leaving it
    sends zero speed and releases speed control if this client took it, then stops the Notifier,
    which stops its listeners (python-can's convention: a CAN log closes).
    """

    def __init__(self, bus: can.BusABC | None = None, *, tx_id: int = HOST_TX_ID,
                 rx_id: int = HOST_RX_ID, timeout: float = 0.1, retries: int = 2,
                 listeners: Iterable[can.Listener] = (), legacy_attitude_order: str = LEGACY_ORDER_DOCUMENT,
                 **bus_kwargs: Any) -> None:
        timeout, retries = _checked_wait(timeout, retries)
        self.legacy_attitude_order = check_legacy_order(legacy_attitude_order)  # of legacy angle replies
        self._owns_bus = bus is None
        if bus is None:
            try:
                bus = can.Bus(**with_default_bitrate(bus_kwargs))
            except (can.CanError, OSError, ValueError, ImportError) as exc:
                raise BusError(f"cannot open the CAN bus: {exc}") from exc
        elif bus_kwargs:
            raise TypeError(f"bus options {sorted(bus_kwargs)} given together with a bus")
        self.bus = bus
        self.timeout = timeout
        self.retries = retries
        self.stats: Counter[str] = Counter()
        self.transport = CanTransport(bus, tx_id=tx_id, rx_id=rx_id)
        self.replies = ReplyMatcher(rx_id, self.stats)
        self.pushes = PushHub(rx_id, self.stats)
        self._closing = threading.Event()
        self._closed = False
        self._rx_error: BaseException | None = None
        self._speed_engaged = False
        self._tx_lock = threading.Lock()  # a command's checks and its send, against close()
        self._stops_only = False  # set by close(): other threads' commands must not follow its stop
        self._streamer: SpeedStreamer | None = None
        self._watch = _BusWatch(self._on_receive_error)
        self.other_hosts = OtherHosts(tx_id)
        self._taps = _Taps(self.transport, self.other_hosts)
        for listener in listeners:
            self._tap(listener)
        try:
            self.notifier = can.Notifier(bus, [self._watch, self._taps, self.replies, self.pushes],
                                         timeout=RX_POLL_S)
        except ValueError as exc:  # python-can: the bus already has a running Notifier
            if self._owns_bus:
                bus.shutdown()
            raise BusError(f"cannot receive on the CAN bus: {exc}") from exc
        atexit.register(self.close)

    def add_listener(self, listener: can.Listener) -> None:
        """Give ``listener`` every frame the bus receives from now on, and every frame this client
        sends (``is_rx=False``), e.g. a ``can.Logger``; it is stopped when the client closes."""
        self._tap(listener)

    def _tap(self, listener: can.Listener) -> None:
        self._taps.listeners.append(listener)
        self.transport.add_sent_listener(listener)

    # -- lifecycle ---------------------------------------------------------------------------

    def __enter__(self) -> Self:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()

    def close(self) -> None:
        """Safety stop, stop the Notifier (and its listeners), shut down the bus if this client
        built it. Commands other threads send from the start of the stop on are refused
        (``GimbalError``), so the stop is the last thing this client sends."""
        if self._closed:
            return
        try:
            self._stop_streamer()
            with self._tx_lock:  # a command already past its checks has been sent by now
                self._stops_only = True
            self.safety_stop()
        finally:
            self._closed = True
            self._closing.set()
            self._taps.close_at_packet_end()
            self.replies.fail_all(GimbalError("client closed"))
            self.pushes.interrupt(GimbalError("the gimbal client is closed"))
            if self._on_receive_thread():  # close() from a push callback: the Notifier cannot join itself
                threading.Thread(target=self._stop_receiving, name="gimbal-close", daemon=True).start()
            else:
                self._stop_receiving()
            atexit.unregister(self.close)

    def _stop_receiving(self) -> None:
        self.notifier.stop(timeout=NOTIFIER_STOP_S)
        if self._owns_bus:
            self.bus.shutdown()

    def safety_stop(self) -> None:
        """Stop the streamer, then send zero speed and release speed control if this client took
        it. Best effort: failures are logged, never raised."""
        self._stop_streamer()
        if self._speed_engaged:
            self.stop_and_release()

    def _stop_streamer(self) -> None:
        streamer = self._streamer
        if streamer is not None:
            streamer.stop()

    def stop_and_release(self) -> None:
        """Zero speed (still in control), then zero with control released (bit 7 clear).

        While the bus is receiving, each is resent (same SEQ) every ``STOP_RESEND_S`` until the
        gimbal answers: the zero for up to half of ``STOP_RETRY_S``, the release until
        ``STOP_RETRY_S`` after the start (a failure is logged); once the bus is known lost, or the
        client closed, they are only sent, best effort: a stop asked for explicitly always goes out
        while the bus can carry it (on a bus this client does not own, one still open), since an
        extra stop costs a controller one tick and a missing one can leave the gimbal in SDK
        speed control. ``stats`` counts those that went out (``stop_zero_sent``,
        ``stop_release_sent``), answered or not, and the resends (``stop_resends``): one the
        gimbal left unanswered or refused is on the bus (and in the CAN log) all the same.
        """
        deadline = time.monotonic() + STOP_RETRY_S
        for message, until in zip(stop_messages(), (deadline - STOP_RETRY_S / 2, deadline)):
            name = "stop_zero_sent" if message.ctrl_byte & SPEED_TAKE_CONTROL else "stop_release_sent"
            try:
                if self._rx_error is None and not self._closed and not self._on_receive_thread():
                    self._stop_until_answered(message, until)
                else:
                    self.transport.send(self.replies.encode(message)[1])
            except (GimbalError, can.CanError, OSError) as exc:
                log.warning("safety stop (%s): %s", "zero speed" if message.ctrl_byte & SPEED_TAKE_CONTROL
                            else "release control", exc)
                if not isinstance(exc, (GimbalTimeoutError, ReturnCodeError)):
                    continue  # not sent
            self.stats[name] += 1
        self._speed_engaged = False

    def _stop_until_answered(self, message: SpeedControl, until: float) -> None:
        """Send ``message`` and resend the same packet until it is answered or ``until`` passes
        (``GimbalTimeoutError``); a refusal raises ``ReturnCodeError``."""
        started = time.monotonic()
        waiter = self.submit(message)
        try:
            while not waiter.wait(max(0.0, min(STOP_RESEND_S, until - time.monotonic()))):
                now = time.monotonic()
                if now >= until:
                    raise GimbalTimeoutError(f"{message.NAME}: no reply within {(now - started) * 1000:.0f} ms "
                                             f"(sent every {STOP_RESEND_S * 1000:.0f} ms)")
                self.stats["stop_resends"] += 1
                self.replies.expect(waiter)
                self._transmit(message, waiter.raw)
        finally:
            self.cancel(waiter)
        self.result(waiter)

    @property
    def alive(self) -> bool:
        """False once closed or once the bus is lost."""
        return not self._closed and self._rx_error is None

    def _check_alive(self) -> None:
        if self._closed:
            raise GimbalError("the gimbal client is closed")
        if self._rx_error is not None:
            raise BusError(f"the receive thread stopped: {self._rx_error}") from self._rx_error

    # -- receiving -------------------------------------------------------------------------

    def _on_receive_thread(self) -> bool:
        return threading.current_thread() is self._watch.thread

    def _on_receive_error(self, exc: Exception) -> None:
        """An error on the Notifier's thread. A bus that fails to receive is tried again until
        ``RX_GIVE_UP_S`` of errors in a row (a passing error must not end a session); then, or at
        once for any other error (a push callback's ``sys.exit()``), the bus is lost."""
        if self._closing.is_set() or self._rx_error is not None:
            self._closing.wait(RX_POLL_S)  # lost already: the Notifier runs on until close()
            return
        if isinstance(exc, (can.CanError, OSError)):
            now = time.monotonic()
            if self._watch.failing_since is None:
                self._watch.failing_since = now
            if now - self._watch.failing_since < RX_GIVE_UP_S:
                self.stats["receive_errors"] += 1
                log.warning("CAN receive failed, trying again: %s", exc)
                self._closing.wait(RX_POLL_S)
                return
        self._lose_bus(exc)

    def _lose_bus(self, exc: Exception) -> None:
        """Recorded, and re-raised as ``BusError`` on the next call; waiters fail, the streamer
        halts and the gimbal gets its best-effort stop."""
        with self._tx_lock:  # a command already past its checks is on the bus before the stop
            self._rx_error = exc
        log.error("gimbal receive thread stopped: %r", exc)
        self.replies.fail_all(exc)
        self.pushes.interrupt(BusError(f"the receive thread stopped: {exc}"))
        streamer = self._streamer
        if streamer is not None:
            streamer.halt(BusError(f"the receive thread stopped: {exc}"))
        if self._speed_engaged:
            self.stop_and_release()

    # -- sending ---------------------------------------------------------------------------

    def _transmit(self, message: Message, raw: bytes) -> None:
        with self._tx_lock:
            self._check_alive()
            if self._stops_only and not _is_stop(message):
                raise GimbalError("the gimbal client is closing")
            if isinstance(message, SpeedControl) and message.ctrl_byte & SPEED_TAKE_CONTROL:
                self._speed_engaged = True
            try:
                self.transport.send(raw)
            except (can.CanError, OSError) as exc:  # third-party interfaces may raise plain OSErrors
                raise SendError(f"CAN send failed: {exc}") from exc

    def submit(self, message: Message, *, cmd_type: int | None = None) -> PendingReply:
        """Send a command that wants a reply and return at once; collect it with ``result``
        (or drop it with ``cancel``)."""
        if message.REPLY is None:
            raise ValueError(f"{message.NAME} has no reply; use send()")
        seq, raw = self.replies.encode(message, cmd_type)
        waiter = PendingReply(message, seq, raw)
        self.replies.expect(waiter)
        try:
            self._transmit(message, raw)
        except BaseException:
            self.cancel(waiter)
            raise
        return waiter

    def cancel(self, waiter: PendingReply) -> None:
        """Stop waiting for ``waiter``'s reply; one arriving later is counted late and dropped."""
        self.replies.cancel(waiter)

    def result(self, waiter: PendingReply) -> Reply:
        """The decoded reply of a completed waiter; ``ReturnCodeError`` for a non-zero code."""
        if waiter.error is not None:
            raise BusError(f"{waiter.request.NAME}: {waiter.error}") from waiter.error
        if waiter.packet is None:
            raise GimbalTimeoutError(f"{waiter.request.NAME}: no reply yet")
        reply = decode_message(waiter.packet, waiter.request, self.legacy_attitude_order)
        code = getattr(reply, "return_code", None)
        if code is None:
            raise GimbalError(f"{waiter.request.NAME}: answered by {reply.NAME}, not a reply")
        if code != 0:
            raise ReturnCodeError(waiter.request.NAME, code)
        return reply  # type: ignore[return-value]

    def request(self, message: Message, *, timeout: float | None = None,
                retries: int | None = None, optional: bool = False) -> Reply | None:
        """Send a command and return its reply.

        Waits ``timeout`` s (default ``self.timeout``) per attempt and resends up to ``retries``
        times with the same SEQ, then raises ``GimbalTimeoutError``. ``optional`` sends CmdType
        0x01 (reply optional) and returns None on silence instead of raising.
        """
        if self._on_receive_thread():
            raise GimbalError(f"{message.NAME}: a push callback cannot wait for a reply (it runs on "
                              "the thread that receives them); hand the work to another thread")
        timeout, retries = _checked_wait(self.timeout if timeout is None else timeout,
                                         self.retries if retries is None else retries)
        waiter = self.submit(message, cmd_type=REPLY_OPTIONAL if optional else None)
        try:
            for attempt in range(retries + 1):
                if attempt:
                    self.stats["retries"] += 1
                    log.warning("%s: no reply within %.0f ms, resending (attempt %d of %d)", message.NAME,
                                timeout * 1000, attempt + 1, retries + 1)
                    self.replies.expect(waiter)
                    self._transmit(message, waiter.raw)
                if waiter.wait(timeout):
                    break
        finally:
            self.cancel(waiter)
        if not waiter.done:
            if optional:
                return None
            raise GimbalTimeoutError(f"{message.NAME}: no reply within {timeout * 1000:.0f} ms "
                                     f"({retries + 1} attempt{'s' if retries else ''})")
        return self.result(waiter)

    def send(self, message: Message) -> None:
        """Send a host push (joystick, dial, version, focus position): CmdType 0x00, no reply."""
        if message.REPLY is not None:
            raise ValueError(f"{message.NAME} wants a reply; use request()")
        self._transmit(message, self.replies.encode(message)[1])

    def send_best_effort(self, message: Message) -> None:
        """Send a host push even once the receive side is lost: for the zero push that ends a
        joystick or dial stream (those pushes have no timeout on the gimbal). A failure is
        logged, never raised."""
        if message.REPLY is not None:
            raise ValueError(f"{message.NAME} wants a reply; use request()")
        try:
            self.transport.send(self.replies.encode(message)[1])
        except (GimbalError, can.CanError, OSError) as exc:
            log.warning("%s not sent: %s", message.NAME, exc)

    # -- pushes ----------------------------------------------------------------------------

    def on_push(self, cls: type[Message], callback: PushCallback) -> Callable[[], None]:
        """Call ``callback(msg, t)`` (t = ``time.monotonic()`` at arrival) for every ``cls`` push,
        on the Notifier's thread; exceptions are logged. Keep it quick: replies wait while it runs,
        and it cannot make requests (``GimbalError``). ``sys.exit()`` in it cannot end the program
        from that thread: it stops the gimbal as a lost bus does, and later calls raise
        ``BusError`` naming the callback. Returns an unsubscribe function."""
        if not callable(callback):
            raise TypeError(f"a push callback must be callable, not {callback!r}")
        return self.pushes.subscribe(cls, callback)

    def latest(self, cls: type[Message]) -> tuple[Message, float] | None:
        """The newest ``cls`` push and its arrival time, or None."""
        return self.pushes.latest(cls)

    def wait_for_push(self, cls: type[Message], timeout: float) -> tuple[Message, float]:
        """The next ``cls`` push; ``GimbalTimeoutError`` after ``timeout`` s, the client's error at
        once if it is closed or loses the bus meanwhile. ``timeout`` must be a number, 0 to
        ``MAX_TIMEOUT`` s (``ValueError``)."""
        if not number(0, MAX_TIMEOUT)(timeout):
            raise ValueError(f"a push timeout must be 0 to {MAX_TIMEOUT:.0f} s, not {shown(timeout)}")
        self._check_alive()
        return self.pushes.wait(cls, timeout)

    # -- the speed keep-alive ----------------------------------------------------------------

    def speed_streamer(self, rate_hz: float = 25.0, max_age: float = DEFAULT_MAX_AGE_S,
                       bus_timeout: float = DEFAULT_TIMEOUT_S) -> SpeedStreamer:
        """Start the speed keep-alive (see ``gimbal.keepalive``); one per client at a time. Its
        ``watchdog`` releases the gimbal after ``bus_timeout`` s without a reply."""
        self._check_alive()
        if self._streamer is not None and self._streamer.running:
            raise GimbalError("a speed streamer is already running; stop() it first")
        self._streamer = SpeedStreamer(self, rate_hz=rate_hz, max_age=max_age,
                                       watchdog=BusWatchdog(bus_timeout))
        return self._streamer
