"""The simulated gimbal on a CAN bus: a receive thread answering commands and a tick thread
sending pushes and delayed replies when they are due, and adding foreign traffic."""
from __future__ import annotations

import heapq
import logging
import threading
import time
import uuid
from collections import Counter
from collections.abc import Callable

import can

from gimbal.framer import Dropped, PacketFramer
from gimbal.messages import Kind, Message, Sender, decode_message, message_packet
from gimbal.messages.firmware import empty_get_request
from gimbal.packet import REPLY_CMD_TYPE, Packet, encode_packet
from gimbal.sim.config import SimConfig
from gimbal.sim.faults import FaultInjector, Faults
from gimbal.sim.model import GimbalModel
from gimbal.sim.state import SimState
from gimbal.transport import CAN_FRAME_DATA, bus_send_lock

log = logging.getLogger(__name__)

RECV_POLL_S = 0.05
SEND_TIMEOUT_S = 0.05
PARSE_ERROR_PAYLOAD = b"\x01"


class SimulatedGimbal:
    """A DJI RS gimbal answering the R SDK on ``bus`` (listens on ``config.rx_id``, answers on
    ``config.tx_id``). ``clock`` drives the model; it must run at the real rate (the tick thread
    sleeps for the clock's seconds until the next push is due)."""

    def __init__(self, bus: can.BusABC, config: SimConfig = SimConfig(), faults: Faults = Faults(),
                 clock: Callable[[], float] = time.monotonic, *, shutdown_bus: bool = False) -> None:
        self.bus = bus
        self.config = config
        self.faults = faults
        self.clock = clock
        self._shutdown_bus = shutdown_bus
        self._injector = FaultInjector(faults)
        self._framer = PacketFramer()
        self._model = GimbalModel(config, clock())
        self._lock = threading.Lock()  # model, framer, counters, delayed replies
        self._send_lock = bus_send_lock(bus)  # shared by all senders on bus: packets never interleave
        self._sent: Counter[str] = Counter()
        self._discarded: Counter[str] = Counter()
        self._delayed: list[tuple[float, int, Packet, str]] = []
        self._push_seq = 0
        self._started_at = 0.0
        self._stop = threading.Event()
        self._wake = threading.Event()  # something is due before the tick thread meant to wake
        self._sleep_until: float | None = None  # when it means to wake (None: when woken)
        self._threads: list[threading.Thread] = []

    def start(self) -> SimulatedGimbal:
        """Start answering; returns self. Once stopped it cannot be started again."""
        if self._stop.is_set():
            raise RuntimeError("a stopped simulated gimbal cannot be started again; make a new one")
        if self._threads:
            raise RuntimeError("simulated gimbal already started")
        self._started_at = self.clock()
        self._threads = [threading.Thread(target=self._rx_loop, name="sim-gimbal-rx", daemon=True),
                         threading.Thread(target=self._tick_loop, name="sim-gimbal-tick", daemon=True)]
        for thread in self._threads:
            thread.start()
        return self

    def stop(self) -> None:
        """Stop both threads (and shut the bus down if this gimbal owns it)."""
        self._stop.set()
        self._wake.set()
        for thread in self._threads:
            thread.join(timeout=2.0)
        if self._shutdown_bus:
            self.bus.shutdown()

    def __enter__(self) -> SimulatedGimbal:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def state(self) -> SimState:
        """A consistent snapshot of everything the device knows."""
        with self._lock:
            faults = self._injector.counts + self._discarded
            faults.update({f"framer_{k}": v for k, v in self._framer.stats.items() if k != "packets"})
            return self._model.snapshot(self.clock(), self._sent, faults)

    # --- receive ------------------------------------------------------------------------------

    def _rx_loop(self) -> None:
        while not self._stop.is_set():
            try:
                frame = self.bus.recv(RECV_POLL_S)
            except (can.CanError, OSError, ValueError) as exc:
                if self._stop.is_set():
                    return
                log.warning("simulated gimbal: receive failed: %s", exc)
                time.sleep(RECV_POLL_S)
                continue
            if frame is not None:
                self._on_frame(frame)

    def _on_frame(self, frame: can.Message) -> None:
        if frame.arbitration_id == self.config.tx_id and not frame.is_extended_id:
            return  # our own frame handed back by an echoing bus (udp_multicast): not a fault
        with self._lock:
            if frame.arbitration_id != self.config.rx_id or frame.is_extended_id \
                    or frame.is_error_frame or frame.is_remote_frame:
                self._discarded["foreign_frames"] += 1
                return
            now = self.clock()
            if self._injector.silent(now - self._started_at):
                self._discarded["silent_rx"] += 1
                return
            data = self._injector.frame(bytes(frame.data), "rx")
            if data is None:
                return
            for item in self._framer.feed_frame(data):
                if not isinstance(item, Dropped):
                    self._on_packet(item, now)

    def _on_packet(self, packet: Packet, now: float) -> None:
        if packet.is_reply:
            self._discarded["replies_received"] += 1
            return
        wants_reply = packet.reply_policy >= 1
        try:
            message = self._lenient_get(packet) or decode_message(packet)
            message.validate()
        except ValueError as exc:  # PayloadError, RangeError
            self._discarded["unparsable"] += 1
            log.debug("simulated gimbal: cannot parse %s: %s", packet.data.hex(" "), exc)
            if wants_reply and len(packet.data) >= 2:
                reply = Packet.reply(packet.cmd_set, packet.cmd_id, PARSE_ERROR_PAYLOAD, packet.seq,
                                     legacy=self._legacy())
                self._queue(reply, "parse_error_reply", now)
            return
        if message.SENDER is Sender.DEVICE:
            self._discarded["device_messages_received"] += 1
            return
        if message.KIND is Kind.PUSH:
            self._model.apply_push(message, now)
            return
        code = self._injector.nack()
        reply = self._model.handle(message, now) if code is None else self._model.refuse(message, code)
        self._wake_if_sooner()  # e.g. the push turned on, a calibration started
        if wants_reply:
            self._queue(message_packet(reply, packet.seq, legacy=self._legacy(),
                                       legacy_order=self.config.legacy_attitude_order), reply.NAME, now)

    def _lenient_get(self, packet: Packet) -> Message | None:
        """In lenient mode, a get request without its payload as the request with the document's
        defaults (ctrl_byte 1; the user parameters this project reads); None otherwise."""
        if not self.config.lenient or len(packet.data) < 2:
            return None
        request = empty_get_request(packet.cmd_set, packet.cmd_id, packet.payload)
        if request is None:
            return None
        self._discarded["empty_get_requests"] += 1
        return request()

    def _legacy(self) -> bool:
        return self._injector.legacy_reply() or self.config.legacy

    # --- transmit -------------------------------------------------------------------------------

    def _queue(self, packet: Packet, name: str, now: float) -> None:
        """Send a reply now, or after the injected delay (from the tick thread)."""
        if self.faults.delay_s <= 0:
            self._send(packet, name, now)
            return
        self._injector.counts["delayed_replies"] += 1
        heapq.heappush(self._delayed, (now + self.faults.delay_s, id(packet), packet, name))
        self._wake_if_sooner()

    def _send(self, packet: Packet, name: str, now: float, stream: str = "replies") -> None:
        if self._injector.silent(now - self._started_at):
            self._discarded["silent_tx"] += 1
            return
        raw = encode_packet(packet)
        frames = [can.Message(arbitration_id=self.config.tx_id, is_extended_id=False, data=data)
                  for i in range(0, len(raw), CAN_FRAME_DATA)
                  if (data := self._injector.frame(raw[i:i + CAN_FRAME_DATA], stream)) is not None]
        self._sent[name] += 1
        self._bus_send(frames)

    def _bus_send(self, frames: list[can.Message]) -> None:
        with self._send_lock:
            try:
                for frame in frames:
                    self.bus.send(frame, timeout=SEND_TIMEOUT_S)
            except (can.CanError, OSError) as exc:
                self._discarded["send_errors"] += 1
                log.warning("simulated gimbal: send failed: %s", exc)

    def _push(self, message: Message, now: float) -> None:
        self._push_seq = (self._push_seq + 1) & 0xFFFF
        cmd_type = REPLY_CMD_TYPE if self.config.push_reply_bit else None
        self._send(message_packet(message, self._push_seq, cmd_type), message.NAME, now, "pushes")

    # --- tick ---------------------------------------------------------------------------------

    def _tick_loop(self) -> None:
        """Sleep until something is due (a push, a delayed reply, the next grain of foreign
        traffic) or a command brings that forward, then send what is due. The model is exact at
        any time, so there is nothing to do in between."""
        grain = 1.0 / self.config.tick_hz
        last = self.clock()
        while not self._stop.is_set():
            now = self.clock()
            with self._lock:
                self._wake.clear()
                for push in self._model.advance(now):
                    self._push(push, now)
                while self._delayed and self._delayed[0][0] <= now:
                    _, _, packet, name = heapq.heappop(self._delayed)
                    self._send(packet, name, now)
                foreign = self._injector.foreign_frames(max(0.0, now - last))
                due = [t for t in (self._next_due(), now + grain if self.faults.foreign_rate > 0 else None)
                       if t is not None]
                self._sleep_until = min(due, default=None)
                until = self._sleep_until
            last = now
            if foreign:
                self._bus_send([can.Message(arbitration_id=i, is_extended_id=False, data=d) for i, d in foreign])
            # at most TIMEOUT_MAX: a longer wait (--delay-ms 1e300) is an OverflowError that ends the thread
            self._wake.wait(None if until is None else min(max(0.0, until - self.clock()), threading.TIMEOUT_MAX))

    def _next_due(self) -> float | None:
        """When the next push or delayed reply is due (lock held)."""
        due = [t for t in (self._model.next_due(), self._delayed[0][0] if self._delayed else None) if t is not None]
        return min(due, default=None)

    def _wake_if_sooner(self) -> None:
        """Wake the tick thread when something is now due before it means to wake (lock held)."""
        due = self._next_due()
        if due is not None and (self._sleep_until is None or due < self._sleep_until):
            self._wake.set()


def start_in_process(config: SimConfig | None = None, faults: Faults | None = None) -> tuple[can.BusABC, SimulatedGimbal]:
    """A started simulated gimbal on a fresh python-can ``virtual`` channel, and the host's end
    of that channel. Stop the gimbal (it closes its own end) and shut the host bus down."""
    channel = f"gimbaltrack-sim-{uuid.uuid4().hex}"
    device_bus = can.Bus(interface="virtual", channel=channel)
    host_bus = can.Bus(interface="virtual", channel=channel)
    sim = SimulatedGimbal(device_bus, config or SimConfig(), faults or Faults(), shutdown_bus=True)
    return host_bus, sim.start()
