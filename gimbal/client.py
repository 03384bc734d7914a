"""The host side of the DJI R SDK over CAN: requests and replies, pushes, and the safety stop.

Angles are degrees and speeds °/s in this API, any real numbers (numpy's too; not bools); they
are converted to the wire's 0.1 units by rounding to the nearest unit and range-checked by the
messages (``RangeError``, as is anything not a finite number) before anything is sent.

Replies are matched to requests by SEQ when the gimbal echoes it, otherwise by CmdSet/CmdID
(latest layout) or to the oldest outstanding request (legacy layout, which has no CmdSet/CmdID).
Once the gimbal has echoed a SEQ, a reply with an unknown SEQ is stale; ``ECHO_EVIDENCE`` replies
in a row that could only be paired by command (a gimbal with a fixed SEQ or its own counter, one
of which matched by chance) switch that back. Before the first echo, a reply to another host on
a shared bus cannot be told from a non-echoing gimbal's and is paired by command; when our own
reply then arrives echoing our SEQ, echoing is learnt (``misattributed_replies``), so that costs
the requests then waiting for that command (usually one), not every later one.
A retry resends the *same* packet with the same SEQ, so a late reply to any attempt completes the
call. Commands whose repetition changes the outcome (relative moves, toggles, camera actions)
are never retried. Replies that match no outstanding request (``stale_replies``), or are too short
to name the command they answer (``bad_replies``), are counted in ``stats`` and dropped.
"""
from __future__ import annotations

import atexit
import logging
import threading
import time
from collections import Counter, deque
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from types import TracebackType
from typing import TYPE_CHECKING, Any, TypeVar

import can

from gimbal.errors import BusError, GimbalError, GimbalTimeoutError, RangeError, ReturnCodeError, SendError
from gimbal.framer import Dropped
from gimbal.messages import (Message, PayloadError, Reply, decode_message, is_device_push,
                             message_packet, reply_fits, reply_key)
from gimbal.messages.camera import CameraAction, CameraActionCode, CameraStatusQuery
from gimbal.messages.firmware import LEGACY_ORDER_DOCUMENT, check_legacy_order
from gimbal.messages.external import (FOCUS_CALIBRATION_COMMANDS, DialPush, FocusCalibration,
                                      FocusPositionControl, FocusPositionQuery, FocusPositionReply,
                                      JoystickPush)
from gimbal.messages.motion import (ANGLES_ATTITUDE, ANGLES_JOINT, AXES, POSITION_ABSOLUTE,
                                    POSITION_INVALID, SPEED_IGNORE_FOCAL_LENGTH, SPEED_TAKE_CONTROL,
                                    GetAngles, PositionControl, SpeedControl, from_raw, to_raw)
from gimbal.messages.settings import (FOLLOW_FPV, FOLLOW_LOCK, FOLLOW_YAW, SELFIE, ActiveTrack,
                                      AngleLimitsReply, GetAngleLimits, GetMotorStiffness,
                                      MotorStiffnessReply, RecenterSelfie, SetAngleLimits,
                                      SetFollowMode, SetMotorStiffness, SetWorkMode)
from gimbal.messages.telemetry import (DEVICE_ID_R_SDK, PUSH_DISABLE, PUSH_ENABLE, PushControl,
                                       VersionPush, VersionQuery, VersionReply)
from gimbal.messages.tlv_params import (AutoCalibration, GetUserParams, SetUserParams, Tlv,
                                        autotune)
from gimbal.packet import REPLY_OPTIONAL, Packet, encode_packet
from gimbal.pushes import PushCallback, PushHub
from gimbal.transport import HOST_RX_ID, HOST_TX_ID, CanTransport, with_default_bitrate
from gimbal.values import integer, is_flag, number

if TYPE_CHECKING:
    from gimbal.keepalive import SpeedStreamer

log = logging.getLogger(__name__)

FIRST_SEQ = 0x1122  # DJI's demo starts here
RX_POLL_S = 0.05  # how often the receive thread looks at the closing flag
RX_GIVE_UP_S = 0.25  # receive errors for this long, without a frame between, mean the bus is lost
ECHO_EVIDENCE = 3  # replies in a row paired only by command that show the gimbal does not echo SEQs
PAIRED_BY_COMMAND_KEPT = 16  # SEQs of the latest requests paired by command, for a late echo
MAX_TIMEOUT = threading.TIMEOUT_MAX  # longer waits overflow the platform's time_t
ANGLE_KINDS = {"attitude": ANGLES_ATTITUDE, "joint": ANGLES_JOINT}
FOLLOW_MODES = {"lock": FOLLOW_LOCK, "yaw": FOLLOW_YAW, "fpv": FOLLOW_FPV}
ORIENTATIONS = {"keep": 0x00, "landscape": 0x01, "landscape-flipped": 0x02, "portrait": 0x03,
                "portrait-flipped": 0x04, "toggle": 0x05, "default": 0xFF}
FOCUS_CALIBRATIONS = {name.replace("_", "-"): code for code, name in FOCUS_CALIBRATION_COMMANDS.items()}
SPEED_HOLD = SPEED_TAKE_CONTROL | SPEED_IGNORE_FOCAL_LENGTH  # 0x88: in control
SPEED_RELEASE = SPEED_IGNORE_FOCAL_LENGTH  # 0x08: bit 7 clear, control released
DEFAULT_MAX_AGE_S = 0.3  # the speed keep-alive replaces a setpoint this old by zero

R = TypeVar("R", bound=Reply)


@dataclass(frozen=True)
class Angles:
    """Gimbal angles in degrees; ``kind`` is "attitude" or "joint"."""

    kind: str
    yaw: float
    roll: float
    pitch: float


def position_message(yaw: float = 0.0, roll: float = 0.0, pitch: float = 0.0, *,
                     absolute: bool = True, time_s: float = 2.0,
                     axes: Iterable[str] = AXES) -> PositionControl:
    """Position control in degrees; axes not listed are flagged invalid (left where they are)."""
    moving = set(axes)
    unknown = moving - set(AXES)
    if unknown:
        raise RangeError(f"unknown axes {sorted(unknown)}; use yaw, roll, pitch")
    ctrl = POSITION_ABSOLUTE if absolute else 0
    raw = {}
    for axis, value in zip(AXES, (yaw, roll, pitch)):
        raw[axis] = to_raw(value, f"{axis} angle") if axis in moving else 0
        if axis not in moving:
            ctrl |= POSITION_INVALID[axis]
    return PositionControl(raw["yaw"], raw["roll"], raw["pitch"], ctrl, to_raw(time_s, "time"))


def flag(value: bool, name: str) -> bool:
    """``value`` as a bool when it is True or False (numpy's too); ``TypeError`` for anything else,
    such as the string "no", which Python would take as true."""
    if not is_flag(value):
        raise TypeError(f"{name} must be True or False, not {value!r}")
    return bool(value)


def speed_message(yaw: float, pitch: float, roll: float = 0.0, *,
                  take_control: bool = True) -> SpeedControl:
    """Speed control in °/s (±360); bit 7 of ctrl_byte takes (or releases) control."""
    ctrl = SPEED_HOLD if flag(take_control, "take_control") else SPEED_RELEASE
    return SpeedControl(to_raw(yaw, "yaw speed"), to_raw(roll, "roll speed"),
                        to_raw(pitch, "pitch speed"), ctrl)


def stop_messages() -> tuple[SpeedControl, SpeedControl]:
    """The safety stop: zero speed still in control, then zero with control released."""
    return SpeedControl(0, 0, 0, SPEED_HOLD), SpeedControl(0, 0, 0, SPEED_RELEASE)


def _is_stop(message: Message) -> bool:
    return message in stop_messages()


def lookup(table: dict[str, int], value: str | int, what: str) -> int:
    """A named choice (or its raw number) from ``table``; RangeError otherwise."""
    if integer(0)(value):  # numpy's too
        if value in table.values():
            return int(value)
    elif isinstance(value, str) and value in table:
        return table[value]
    raise RangeError(f"{what} {value!r} is not one of {', '.join(table)}")


def _checked_wait(timeout: float, retries: int) -> tuple[float, int]:
    """A reply timeout (s, above 0, at most ``MAX_TIMEOUT``) and retry count (an int, 0 or more) as
    float and int; ``ValueError`` naming what is wrong otherwise."""
    if not number(0, MAX_TIMEOUT, above=True)(timeout):
        raise ValueError(f"timeout must be above 0 and at most {MAX_TIMEOUT:.0f} s, not {timeout!r}")
    if not integer(0)(retries):
        raise ValueError(f"retries must be a whole number, 0 or more, not {retries!r}")
    return float(timeout), int(retries)


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


class GimbalClient:
    """Talks to one DJI RS gimbal over a python-can bus.

    ``bus`` may be any ``can.BusABC``; without one, ``can.Bus(**bus_kwargs)`` is built from
    python-can's own configuration (``interface=``, ``channel=``, can.rc, ``CAN_*`` variables,
    ``~/.canrc``), at the document's 1 Mbit/s unless a bitrate is given or configured, and shut
    down on close. Use as a context manager: leaving it sends zero speed and releases speed
    control if this client took it.
    """

    def __init__(self, bus: can.BusABC | None = None, *, tx_id: int = HOST_TX_ID,
                 rx_id: int = HOST_RX_ID, timeout: float = 0.1, retries: int = 2,
                 legacy_attitude_order: str = LEGACY_ORDER_DOCUMENT, **bus_kwargs: Any) -> None:
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
        self.transport = CanTransport(bus, tx_id=tx_id, rx_id=rx_id)
        self.pushes = PushHub()
        self.stats: Counter[str] = Counter()
        self._lock = threading.Lock()
        self._pending: dict[int, PendingReply] = {}
        self._seq = FIRST_SEQ
        self._seq_echoed = False  # learnt from a reply that echoes its request's SEQ (see _note_echo)
        self._unechoed_run = 0  # replies in a row since then that could only be paired by command
        self._paired_by_command: deque[tuple[int, tuple[int, int] | None]] = \
            deque(maxlen=PAIRED_BY_COMMAND_KEPT)  # (SEQ, reply key) of requests paired by command
        self._closing = threading.Event()
        self._closed = False
        self._rx_error: BaseException | None = None
        self._speed_engaged = False
        self._tx_lock = threading.Lock()  # a command's checks and its send, against close()
        self._stops_only = False  # set by close(): other threads' commands must not follow its stop
        self._streamer: SpeedStreamer | None = None
        self._rx_thread = threading.Thread(target=self._receive_loop, name="gimbal-rx", daemon=True)
        self._rx_thread.start()
        atexit.register(self.close)

    # -- lifecycle ---------------------------------------------------------------------------

    def __enter__(self) -> GimbalClient:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()

    def close(self) -> None:
        """Safety stop, stop the receive thread, shut down the bus if this client built it.
        Commands other threads send from the start of the stop on are refused (``GimbalError``),
        so the stop is the last thing this client sends."""
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
            if threading.current_thread() is not self._rx_thread:  # close() from a push callback
                self._rx_thread.join(timeout=1.0)
            self._fail_all(GimbalError("client closed"))
            self.pushes.interrupt(GimbalError("the gimbal client is closed"))
            if self._owns_bus:
                self.bus.shutdown()
            atexit.unregister(self.close)

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

        With a live receive thread each waits for its reply (no retries: a failure is logged);
        once the bus is known lost, or the client closed, they are only sent, best effort: a
        stop asked for explicitly always goes out while the bus can carry it (on a bus this
        client does not own, one still open), since an extra stop costs a controller one tick and
        a missing one can leave the gimbal in SDK speed control. ``stats`` counts those that went
        out (``stop_zero_sent``, ``stop_release_sent``), answered or not: one the gimbal left
        unanswered or refused is on the bus (and in the CAN log) all the same.
        """
        for message in stop_messages():
            name = "stop_zero_sent" if message.ctrl_byte & SPEED_TAKE_CONTROL else "stop_release_sent"
            try:
                if self._rx_error is None and not self._closed \
                        and threading.current_thread() is not self._rx_thread:
                    self.request(message, retries=0)
                else:
                    self.transport.send(self._encode(message)[1])
            except (GimbalError, can.CanError, OSError) as exc:
                log.warning("safety stop (%s): %s", "zero speed" if message.ctrl_byte & SPEED_TAKE_CONTROL
                            else "release control", exc)
                if not isinstance(exc, (GimbalTimeoutError, ReturnCodeError)):
                    continue  # not sent
            self.stats[name] += 1
        self._speed_engaged = False

    @property
    def alive(self) -> bool:
        """False once closed or once the receive thread died (bus lost)."""
        return not self._closed and self._rx_error is None

    def _check_alive(self) -> None:
        if self._closed:
            raise GimbalError("the gimbal client is closed")
        if self._rx_error is not None:
            raise BusError(f"the receive thread stopped: {self._rx_error}") from self._rx_error

    # -- receiving -------------------------------------------------------------------------

    def _receive_loop(self) -> None:
        try:
            while not self._closing.is_set():
                item = self._receive()
                if isinstance(item, Dropped):
                    self.stats[f"dropped_{item.reason}"] += len(item.data)
                    log.debug("dropped %d bytes (%s)", len(item.data), item.reason)
                elif item is not None:
                    self._dispatch(item, time.monotonic())
        except BaseException as exc:  # recorded, and re-raised as BusError on the next call
            if self._closing.is_set():
                return
            with self._tx_lock:  # a command already past its checks is on the bus before the stop
                self._rx_error = exc
            log.error("gimbal receive thread stopped: %r", exc)
            self._fail_all(exc)
            self.pushes.interrupt(BusError(f"the receive thread stopped: {exc}"))
            self._on_bus_lost()

    def _receive(self) -> Packet | Dropped | None:
        """The next packet; a bus that fails to receive is tried again until ``RX_GIVE_UP_S`` of
        errors in a row (a passing error must not end a session), then its error is raised."""
        failing_since: float | None = None
        while True:
            try:
                return self.transport.recv(RX_POLL_S)
            except (can.CanError, OSError) as exc:
                now = time.monotonic()
                failing_since = now if failing_since is None else failing_since
                if now - failing_since >= RX_GIVE_UP_S or self._closing.is_set():
                    raise
                self.stats["receive_errors"] += 1
                log.warning("CAN receive failed, trying again: %s", exc)
                self._closing.wait(RX_POLL_S)

    def _on_bus_lost(self) -> None:
        streamer = self._streamer
        if streamer is not None:
            streamer.halt(BusError(f"the receive thread stopped: {self._rx_error}"))
        if self._speed_engaged:
            self.stop_and_release()

    def _dispatch(self, packet: Packet, t: float) -> None:
        if is_device_push(packet):
            try:
                message = decode_message(packet)
            except GimbalError as exc:
                self.stats["bad_pushes"] += 1
                log.warning("undecodable push: %s", exc)
                return
            self.stats["pushes"] += 1
            self.pushes.deliver(message, t)
        elif packet.is_reply:
            try:
                waiter = self._match(packet)
            except PayloadError as exc:
                self.stats["bad_replies"] += 1
                log.warning("undecodable reply: %s", exc)
                return
            if waiter is None:
                self.stats["stale_replies"] += 1
                log.debug("reply SEQ 0x%04X matches no outstanding request", packet.seq)
            else:
                waiter.resolve(packet)
        else:
            self.stats["ignored"] += 1

    def _match(self, packet: Packet) -> PendingReply | None:
        """Pop the waiter a reply belongs to.

        By SEQ first. Unless the gimbal is known to echo SEQs, a reply whose SEQ matches
        nothing goes to the oldest request with its CmdSet/CmdID (latest layout) or to the oldest
        request (legacy layout); for a gimbal that echoes, such a reply is stale. A focus motor
        reply (0x12) only answers a request of the sub-command it echoes, a version reply (0x09)
        only the query for the device it names (``reply_fits``). Raises
        ``PayloadError`` for a reply too short to say which command it answers.
        """
        key = reply_key(packet)
        legacy = key is None

        def answers(w: PendingReply) -> bool:
            return (legacy or w.key == key) and reply_fits(w.request, packet)

        with self._lock:
            waiter = self._pending.get(packet.seq)
            echoed = waiter is not None and answers(waiter)
            if not echoed:
                waiter = next((w for w in self._pending.values() if answers(w)), None)
                if waiter is None and (packet.seq, key) in self._paired_by_command:
                    self._late_echo(packet.seq)
            self._note_echo(echoed, waiter is not None)
            if waiter is not None and not echoed and self._seq_echoed:
                waiter = None
            if waiter is not None:
                del self._pending[waiter.seq]
                if not echoed:
                    self._paired_by_command.append((waiter.seq, key))
            return waiter

    def _late_echo(self, seq: int) -> None:
        """A reply echoing the SEQ of a request that an earlier reply, paired by command, already
        completed: the gimbal echoes after all, and that earlier reply was someone else's (another
        host's on a shared bus). Replies with unknown SEQs are stale from now on (lock held)."""
        self.stats["misattributed_replies"] += 1
        log.warning("reply SEQ 0x%04X echoes a request already answered by a reply paired by "
                    "command (another host's?): pairing by SEQ only from now on", seq)
        self._seq_echoed, self._unechoed_run = True, 0
        self._paired_by_command.clear()

    def _note_echo(self, echoed: bool, by_command: bool) -> None:
        """A reply that echoed its request's SEQ shows the gimbal echoes; ``ECHO_EVIDENCE`` in a
        row that could only be paired by command show that was chance (a fixed reply SEQ once
        the client's counter wraps to it), and they are paired by command again."""
        if echoed:
            self._seq_echoed, self._unechoed_run = True, 0
        elif by_command:
            self._unechoed_run += 1
            if self._unechoed_run >= ECHO_EVIDENCE:
                self._seq_echoed = False

    def _fail_all(self, error: BaseException) -> None:
        with self._lock:
            waiters = list(self._pending.values())
            self._pending.clear()
        for waiter in waiters:
            waiter.fail(error)

    # -- sending ---------------------------------------------------------------------------

    def _encode(self, message: Message, cmd_type: int | None = None) -> tuple[int, bytes]:
        """The next free SEQ and the packet bytes of ``message`` with it. Encoding validates: a
        ``RangeError`` leaves the SEQ unused and nothing is sent."""
        with self._lock:
            seq = self._seq
            while seq in self._pending:
                seq = (seq + 1) & 0xFFFF
            raw = encode_packet(message_packet(message, seq, cmd_type))
            self._seq = (seq + 1) & 0xFFFF
            return seq, raw

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
        seq, raw = self._encode(message, cmd_type)
        waiter = PendingReply(message, seq, raw)
        with self._lock:
            self._pending[seq] = waiter
        try:
            self._transmit(message, raw)
        except BaseException:
            self.cancel(waiter)
            raise
        return waiter

    def cancel(self, waiter: PendingReply) -> None:
        """Stop waiting for ``waiter``'s reply; a late reply is then dropped as stale."""
        with self._lock:
            if self._pending.get(waiter.seq) is waiter:
                del self._pending[waiter.seq]

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
        if threading.current_thread() is self._rx_thread:
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
                    with self._lock:
                        self._pending.setdefault(waiter.seq, waiter)
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
        self._transmit(message, self._encode(message)[1])

    def send_best_effort(self, message: Message) -> None:
        """Send a host push even once the receive side is lost: for the zero push that ends a
        joystick or dial stream (those pushes have no timeout on the gimbal). A failure is
        logged, never raised."""
        if message.REPLY is not None:
            raise ValueError(f"{message.NAME} wants a reply; use request()")
        try:
            self.transport.send(self._encode(message)[1])
        except (GimbalError, can.CanError, OSError) as exc:
            log.warning("%s not sent: %s", message.NAME, exc)

    def _ask(self, message: Message, reply_type: type[R]) -> R:
        reply = self.request(message)
        if not isinstance(reply, reply_type):
            raise GimbalError(f"{message.NAME}: unexpected reply {type(reply).__name__}")
        return reply

    def _once(self, message: Message) -> None:
        """A command whose repetition would change the outcome: sent once, never retried."""
        self.request(message, retries=0)

    # -- pushes ----------------------------------------------------------------------------

    def on_push(self, cls: type[Message], callback: PushCallback) -> Callable[[], None]:
        """Call ``callback(msg, t)`` (t = ``time.monotonic()`` at arrival) for every ``cls`` push,
        on the receive thread; exceptions are logged. Keep it quick: replies wait while it runs,
        and it cannot make requests (``GimbalError``). ``sys.exit()`` in it cannot end the program
        from that thread: it ends the receive thread, which stops the gimbal as a lost bus does,
        and later calls raise ``BusError`` naming the callback. Returns an unsubscribe function."""
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
            raise ValueError(f"a push timeout must be 0 to {MAX_TIMEOUT:.0f} s, not {timeout!r}")
        self._check_alive()
        return self.pushes.wait(cls, timeout)

    # -- motion ----------------------------------------------------------------------------

    def position(self, yaw: float = 0.0, roll: float = 0.0, pitch: float = 0.0, *,
                 absolute: bool = True, time_s: float = 2.0, axes: Iterable[str] = AXES) -> None:
        """Move to (absolute) or by (relative) the angles in degrees within ``time_s`` seconds.
        Relative moves are never retried."""
        message = position_message(yaw, roll, pitch, absolute=absolute, time_s=time_s, axes=axes)
        self.request(message, retries=None if absolute else 0)

    def speed(self, yaw: float, pitch: float, roll: float = 0.0, *, take_control: bool = True) -> None:
        """One speed command in °/s; the gimbal keeps it 0.5 s (use ``speed_streamer`` to hold it)."""
        self.request(speed_message(yaw, pitch, roll, take_control=take_control))

    def speed_streamer(self, rate_hz: float = 25.0, max_age: float = DEFAULT_MAX_AGE_S) -> SpeedStreamer:
        """Start the speed keep-alive (see ``gimbal.keepalive``); one per client at a time."""
        from gimbal.keepalive import SpeedStreamer
        self._check_alive()
        if self._streamer is not None and self._streamer.running:
            raise GimbalError("a speed streamer is already running; stop() it first")
        self._streamer = SpeedStreamer(self, rate_hz=rate_hz, max_age=max_age)
        return self._streamer

    def get_angles(self, kind: str = "attitude") -> Angles:
        """Attitude or joint angles in degrees."""
        code = lookup(ANGLE_KINDS, kind, "angle kind")
        reply = self._ask(GetAngles(code), Reply)
        if getattr(reply, "data_type", None) != code or getattr(reply, "pitch", None) is None:
            raise GimbalError(f"the gimbal has no {kind} angles ready (data_type "
                              f"{getattr(reply, 'data_type', None)})")
        name = next(k for k, v in ANGLE_KINDS.items() if v == code)
        return Angles(name, *(from_raw(getattr(reply, axis)) for axis in AXES))

    # -- settings --------------------------------------------------------------------------

    def set_angle_limits(self, pitch_max: int, pitch_min: int, yaw_max: int, yaw_min: int,
                         roll_max: int, roll_min: int) -> None:
        """User angle limits in whole degrees (min values are magnitudes below zero)."""
        self.request(SetAngleLimits(1, pitch_max, pitch_min, yaw_max, yaw_min, roll_max, roll_min))

    def get_angle_limits(self) -> AngleLimitsReply:
        """The user angle limits, whole degrees."""
        return self._ask(GetAngleLimits(), AngleLimitsReply)

    def set_stiffness(self, pitch: int, roll: int, yaw: int) -> None:
        """Motor stiffness 0..100 per axis."""
        self.request(SetMotorStiffness(1, pitch, roll, yaw))

    def get_stiffness(self) -> MotorStiffnessReply:
        """Motor stiffness 0..100 per axis."""
        return self._ask(GetMotorStiffness(), MotorStiffnessReply)

    def set_push(self, enabled: bool) -> None:
        """Enable or disable the parameter push (ParameterPush)."""
        self.request(PushControl(PUSH_ENABLE if flag(enabled, "enabled") else PUSH_DISABLE))

    def version(self, device_id: int = DEVICE_ID_R_SDK) -> VersionReply:
        """A module's version (``reply.version_text`` reads AA.BB.CC.DD)."""
        return self._ask(VersionQuery(device_id), VersionReply)

    def push_version(self, device_id: int, version: int) -> None:
        """Announce an external device's version to the gimbal (unanswered; repeat at 1 Hz)."""
        self.send(VersionPush(device_id, version))

    def joystick(self, yaw: int, pitch: int, roll: int = 0) -> None:
        """External joystick push, raw -15000..15000 per axis (unanswered)."""
        self.send(JoystickPush(pitch_speed=pitch, roll_speed=roll, yaw_speed=yaw))

    def dial(self, speed: int) -> None:
        """External dial push, raw -2048..2048 (unanswered)."""
        self.send(DialPush(dial_speed=speed))

    def get_user_params(self, ids: Iterable[int] | None = None) -> tuple[Tlv, ...]:
        """User parameters as TLVs (describe them with ``tlv_params.describe_user_param``)."""
        message = GetUserParams() if ids is None else GetUserParams(tuple(ids))
        return self.request(message).tlvs  # type: ignore[union-attr]

    def set_user_params(self, tlvs: Iterable[Tlv]) -> tuple[Tlv, ...]:
        """Write user parameters, e.g. ``[motors_off(True)]``; returns the TLVs echoed back."""
        return self.request(SetUserParams(tuple(tlvs))).tlvs  # type: ignore[union-attr]

    def set_work_mode(self, orientation: str | int) -> None:
        """Landscape/portrait orientation (names in ``ORIENTATIONS``)."""
        code = lookup(ORIENTATIONS, orientation, "orientation")
        message = SetWorkMode(orientation=code)
        self.request(message, retries=0 if code == ORIENTATIONS["toggle"] else None)

    def recenter(self) -> None:
        """Recenter once."""
        self.request(RecenterSelfie())

    def selfie(self) -> None:
        """Turn around for a selfie (a toggle: never retried)."""
        self._once(RecenterSelfie(action=SELFIE))

    def set_follow_mode(self, mode: str | int) -> None:
        """Follow mode: "lock", "yaw" or "fpv"."""
        self.request(SetFollowMode(lookup(FOLLOW_MODES, mode, "follow mode")))

    def auto_calibration(self, start: bool = True, type: int = 1) -> None:  # noqa: A002
        """Start or stop auto-tuning (type 1 = single pose, the document's advice). The document
        shows no reply, so it is sent reply-optional and silence is accepted."""
        self.request(AutoCalibration((autotune(flag(start, "start"), type),)), retries=0, optional=True)

    def activetrack_toggle(self) -> None:
        """Toggle ActiveTrack; reply-optional like ``auto_calibration``, never retried."""
        self.request(ActiveTrack(), retries=0, optional=True)

    # -- focus motor and camera ------------------------------------------------------------

    def focus_position(self, position: int) -> None:
        """Focus motor absolute position 0..4095 (a push: unanswered, up to 100 Hz)."""
        self.send(FocusPositionControl(position=position))

    def focus_calibration(self, command: str | int) -> bool:
        """Focus calibration command ("auto", "manual", "set-min", "set-max", "stop"); True if
        the motor reports success."""
        code = lookup(FOCUS_CALIBRATIONS, command, "focus calibration command")
        reply = self.request(FocusCalibration(calibration_cmd=code), retries=0)
        return getattr(reply, "result", 0) in (0, None)

    def focus_read(self) -> FocusPositionReply:
        """Focus motor calibration state and position."""
        return self._ask(FocusPositionQuery(), FocusPositionReply)

    def camera_action(self, code: int | CameraActionCode) -> None:
        """A camera action (photo, record start/stop, centre focus); never retried."""
        self._once(CameraAction(int(code)))

    def photo(self) -> None:
        self.camera_action(CameraActionCode.TAKE_PHOTO)

    def start_recording(self) -> None:
        self.camera_action(CameraActionCode.START_RECORDING)

    def stop_recording(self) -> None:
        self.camera_action(CameraActionCode.STOP_RECORDING)

    def camera_status(self) -> bool:
        """True while the camera records."""
        reply = self.request(CameraStatusQuery())
        recording = getattr(reply, "recording", None)
        if recording is None:
            raise GimbalError("camera status reply carries no status")
        return recording
