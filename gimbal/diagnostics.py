"""The bring-up checks behind ``gimbaltrack doctor``: is this bus, at these ids, a DJI RS gimbal
we can drive, and does nobody else drive it?

Each check is bounded in time and ends in a ``Check`` (passed or not, what was seen, and on failure
a hint naming the likely cause on a real rig). ``BusCensus`` is a ``can.Listener`` on the client's
Notifier that counts every frame by what it is: the gimbal's packets, foreign frames (DJI's own
accessory traffic), error frames, and frames on our transmit id that we did not send. What those
frames carry is judged by the client's own ``OtherHosts`` (the view ``track`` refuses to take
control on): another host is a controller if it sends commands that move the gimbal. No CLI here:
``pipelines.cli.doctor_cmd`` prints the results.
"""
from __future__ import annotations

import statistics
import threading
import time
from collections import Counter
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field
from typing import Any

import can

from gimbal.client import GimbalClient, position_message
from gimbal.errors import GimbalError, GimbalTimeoutError, ReturnCodeError
from gimbal.framer import Dropped, PacketFramer
from gimbal.messages import is_device_push, reply_key
from gimbal.messages.firmware import LEGACY_ORDER_DOCUMENT, LEGACY_ORDER_YPR
from gimbal.messages.limits import ANGLE_RANGES, TENTHS
from gimbal.messages.motion import ANGLES_ATTITUDE, AxisDegrees, GetAngles
from gimbal.messages.telemetry import ParameterPush
from gimbal.packet import Packet
from gimbal.transport import DEFAULT_BITRATE, HOST_RX_ID, HOST_TX_ID

LISTEN_S = 1.0  # the passive census at the start
LATENCY_QUERIES = 50
QUERY_TIMEOUT_S = 0.4  # one attitude query's wait; longer than the client's 0.1 s to measure slow replies
LATENCY_BUDGET_S = 4.0  # the latency check ends after this even if queries remain
GIVE_UP_AFTER = 3  # unanswered queries in a row with none answered at all: nobody is there
SLOW_MS = 100.0  # the client's reply timeout: slower replies cost a retry in track
SLOW_SHARE = 0.1  # more replies than this slower than SLOW_MS fail the check (one is a hiccup of the host)
PUSH_WINDOW_S = 1.0
PUSH_WAIT_S = 0.5  # for the first push once enabled
MIN_PUSH_HZ = 10.0
WIGGLE_DEG = 5.0  # the position step
WIGGLE_TIME_S = 0.5  # time given to each position move
SETTLE_S = 0.4  # after the move's time, before the attitude is read
FOLLOW_TOLERANCE_DEG = 1.0
NUDGE_DPS = 10.0  # the speed nudge that checks the speed signs
NUDGE_S = 0.4


@dataclass
class Check:
    """One line of the report: ``ok`` True (✓) or False (✗); ``hint`` says what to look at."""

    name: str
    ok: bool
    summary: str
    hint: str = ""
    data: dict[str, Any] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class RigSettings:
    """What the run assumes about the rig, as ``track`` takes it: ids, bitrate, the firmware's
    legacy angle order and the sign conventions (``track --invert-yaw`` etc.)."""

    tx_id: int = HOST_TX_ID
    rx_id: int = HOST_RX_ID
    bitrate: int | None = None  # None: not given (python-can's configuration or the 1 Mbit/s default)
    legacy_order: str = LEGACY_ORDER_DOCUMENT
    yaw_sign: int = 1
    pitch_sign: int = 1
    yaw_attitude_sign: int = 1
    pitch_attitude_sign: int = 1
    camera: bool = True  # check camera control too


class BusCensus(can.Listener):
    """Counts every frame the client's Notifier sees (and, marked ``is_rx=False``, every frame the
    client sends). Frames on ids other than ours are reassembled per id too, so that DJI R SDK
    packets on an unexpected id (swapped or wrong ``--rx-id``) can be named."""

    def __init__(self, tx_id: int = HOST_TX_ID, rx_id: int = HOST_RX_ID) -> None:
        self.tx_id, self.rx_id = tx_id, rx_id
        self.counts: Counter[str] = Counter()
        self.foreign_ids: Counter[int] = Counter()
        self.packets_on: Counter[int] = Counter()  # DJI R SDK packets seen on other ids
        self.damaged: Counter[str] = Counter()  # the gimbal's bytes dropped, by reason
        self._framers: dict[int, PacketFramer] = {}
        self._lock = threading.Lock()

    def snapshot(self) -> Counter[str]:
        """A copy of ``counts``; the per-id and per-reason tables are read with ``tables``."""
        with self._lock:
            return Counter(self.counts)

    def tables(self) -> tuple[Counter[int], Counter[int], Counter[str]]:
        """Copies of ``foreign_ids``, ``packets_on`` and ``damaged``."""
        with self._lock:
            return Counter(self.foreign_ids), Counter(self.packets_on), Counter(self.damaged)

    def on_message_received(self, msg: can.Message) -> None:
        with self._lock:
            self._count(msg)

    def _count(self, msg: can.Message) -> None:
        if msg.is_error_frame:
            self.counts["error_frames"] += 1
            return
        if not msg.is_rx:
            self.counts["sent_frames"] += 1
            return
        if msg.is_remote_frame or msg.is_extended_id:
            self.counts["foreign_frames"] += 1
            self.foreign_ids[msg.arbitration_id] += 1
            return
        if msg.arbitration_id == self.tx_id:
            self.counts["other_host_frames"] += 1  # their packets: the client's ``other_hosts``
        elif msg.arbitration_id == self.rx_id:
            self.counts["gimbal_frames"] += 1
            self._feed(msg, self._gimbal_packet)
        else:
            self.counts["foreign_frames"] += 1
            self.foreign_ids[msg.arbitration_id] += 1
            self._feed(msg, lambda packet: self.packets_on.update((msg.arbitration_id,)))

    def _feed(self, msg: can.Message, on_packet: Callable[[Packet], None]) -> None:
        framer = self._framers.setdefault(msg.arbitration_id, PacketFramer())
        for item in framer.feed_frame(bytes(msg.data)):
            if isinstance(item, Dropped):
                if msg.arbitration_id == self.rx_id:
                    self.damaged[item.reason] += 1
            else:
                on_packet(item)

    def _gimbal_packet(self, packet: Packet) -> None:
        self.counts["gimbal_packets"] += 1
        if is_device_push(packet):
            self.counts["pushes"] += 1
        elif packet.is_reply:
            try:
                self.counts["legacy_replies" if reply_key(packet) is None else "latest_replies"] += 1
            except GimbalError:
                self.counts["short_replies"] += 1


def _hex(can_id: int) -> str:
    return f"0x{can_id:03X}"


def nothing_answers_hint(census: BusCensus, rig: RigSettings) -> str:
    """Why a gimbal may not answer, most specific first: replies on another id, ids or bitrate not
    the document's, a bus that carries other traffic, or a silent bus."""
    elsewhere = [i for i, n in census.tables()[1].most_common() if n]
    if elsewhere:
        return (f"DJI R SDK packets arrive on {', '.join(map(_hex, elsewhere))}, not on --rx-id "
                f"{_hex(rig.rx_id)}: set --rx-id (and --tx-id) to the gimbal's")
    hints = []
    if (rig.tx_id, rig.rx_id) != (HOST_TX_ID, HOST_RX_ID):
        hints.append(f"ids {_hex(rig.tx_id)}/{_hex(rig.rx_id)} are not the document's "
                     f"{_hex(HOST_TX_ID)}/{_hex(HOST_RX_ID)} (--tx-id/--rx-id)")
    if rig.bitrate is not None and rig.bitrate != DEFAULT_BITRATE:
        hints.append(f"-b {rig.bitrate} is not the gimbal's {DEFAULT_BITRATE}")
    counts = census.snapshot()
    if counts["foreign_frames"]:
        hints.append("the bus carries other traffic, so it works: check the ids, and that the gimbal "
                     "supports the R SDK (RS 2, RS 3 Pro, RS 4)")
    else:
        hints.append("nothing at all on the bus: gimbal off or unplugged, bitrate (1 Mbit/s), CANH/CANL "
                     "swapped, no 120 Ω terminator, GND not connected")
    return "; ".join(hints)


class Doctor:
    """Runs the checks in order against one client; ``census`` must be among its listeners."""

    def __init__(self, client: GimbalClient, census: BusCensus, rig: RigSettings,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.client, self.census, self.rig, self.clock = client, census, rig, clock
        self.answering = True  # false once nothing answered: the later checks are skipped

    def checks(self, wiggle: bool = False) -> Iterator[Check]:
        """Each check as it completes; the gimbal-facing ones are skipped (failed, with the reason)
        once the gimbal has not answered."""
        yield self.listen()
        yield self.version()
        for step in (self.latency, self.layout, self.push_rate, self.camera, self.integrity):
            if step == self.camera and not self.rig.camera:
                continue
            yield step() if self.answering else Check(step.__name__.split("_")[0], False,
                                                       "skipped: the gimbal does not answer")
        if wiggle:
            yield from (self.wiggle() if self.answering else
                        [Check("wiggle", False, "skipped: the gimbal does not answer")])
        yield self.other_controller()

    # -- passive -------------------------------------------------------------------------

    def listen(self, seconds: float = LISTEN_S) -> Check:
        """Count what is on the bus before we say anything."""
        before = self.census.snapshot()
        time.sleep(seconds)
        seen = self.census.snapshot() - before
        foreign_ids = sorted(self.census.tables()[0])
        foreign = ", ".join(map(_hex, foreign_ids)) or "none"
        summary = (f"{seconds:g} s: {seen['gimbal_packets']} DJI R SDK packets, {seen['foreign_frames']} "
                   f"foreign frames (ids {foreign}), {seen['error_frames']} error frames")
        data = {"seconds": seconds, "sdk_packets": seen["gimbal_packets"], "foreign_frames": seen["foreign_frames"],
                "foreign_ids": [_hex(i) for i in foreign_ids],
                "error_frames": seen["error_frames"], "other_host_frames": seen["other_host_frames"]}
        if seen["error_frames"]:
            return Check("listen", False, summary, "error frames: a bitrate that differs from the bus's "
                         "(the gimbal's is 1 Mbit/s), no 120 Ω terminator, CANH/CANL swapped or loose", data)
        return Check("listen", True, summary, data=data)

    # -- the gimbal answers --------------------------------------------------------------

    def version(self) -> Check:
        try:
            reply = self.client.version()
        except ReturnCodeError as exc:
            return Check("version", False, f"refused: {exc}", "the gimbal is there but refuses the query")
        except GimbalError as exc:
            self.answering = False
            return Check("version", False, f"no answer: {exc}", nothing_answers_hint(self.census, self.rig))
        return Check("version", True, f"DJI R SDK {reply.version_text}", data={"version": reply.version_text})

    def layout(self) -> Check:
        counts = self.census.snapshot()
        legacy, latest = counts["legacy_replies"], counts["latest_replies"]
        data = {"legacy_replies": legacy, "latest_replies": latest}
        if legacy and latest:
            return Check("layout", False, f"mixed: {latest} latest and {legacy} legacy replies",
                         "one gimbal answers in one layout: another device answers on the same id?", data)
        if legacy:
            data["layout"] = "legacy"
            return Check("layout", True, f"legacy (replies without CmdSet/CmdID; --legacy-order "
                         f"{self.rig.legacy_order}, checked by --wiggle)", data=data)
        data["layout"] = "latest"
        return Check("layout", True, "latest (replies carry CmdSet/CmdID)", data=data)

    def latency(self, queries: int = LATENCY_QUERIES) -> Check:
        """Round trips of attitude queries, one at a time, without retries."""
        times_ms: list[float] = []
        lost = refused = 0
        end = self.clock() + LATENCY_BUDGET_S
        sent = 0
        while sent < queries and self.clock() < end:
            sent += 1
            start = time.perf_counter()
            try:
                self.client.request(GetAngles(ANGLES_ATTITUDE), timeout=QUERY_TIMEOUT_S, retries=0)
                times_ms.append((time.perf_counter() - start) * 1000)
            except ReturnCodeError:
                refused += 1
            except GimbalTimeoutError:
                lost += 1
                if lost >= GIVE_UP_AFTER and not times_ms and not refused:
                    break
        data: dict[str, Any] = {"queries": sent, "answered": len(times_ms), "unanswered": lost, "refused": refused}
        slow = sum(t > SLOW_MS for t in times_ms)
        if times_ms:
            p50, p99 = _percentile(times_ms, 50), _percentile(times_ms, 99)
            data.update(p50_ms=round(p50, 2), p99_ms=round(p99, 2), slower_than_timeout=slow)
            summary = f"{len(times_ms)} of {sent} attitude queries answered, p50 {p50:.1f} ms, p99 {p99:.1f} ms"
            if slow:
                summary += f", {slow} slower than {SLOW_MS:.0f} ms"
        else:
            summary = f"none of {sent} attitude queries answered"
        hints = []
        if refused:
            summary += f"; {refused} refused"
            hints.append("the gimbal refuses commands: motors off, calibrating, or in a mode that ignores "
                         "the R SDK (another controller in charge?)")
        if slow > SLOW_SHARE * len(times_ms):
            hints.append(f"replies slower than the client's {SLOW_MS:.0f} ms timeout: a slow adapter or "
                         "driver, or a loaded bus; track will retry")
        if lost:
            summary += f"; {lost} unanswered within {QUERY_TIMEOUT_S * 1000:.0f} ms"
            hints.append("frames are lost: termination (120 Ω), a loose CANH/CANL or GND, bus load, or a "
                         "gimbal that goes silent")
        if hints:
            return Check("latency", False, summary, "; ".join(hints), data)
        return Check("latency", True, summary, data=data)

    def push_rate(self, window: float = PUSH_WINDOW_S) -> Check:
        """Enable the parameter push, count it for ``window`` s; disable it again unless it was on."""
        was_on = self.census.snapshot()["pushes"] > 0
        try:
            self.client.set_push(True)
        except GimbalError as exc:
            return Check("push", False, f"cannot enable the parameter push: {exc}",
                         "the gimbal does not take push control (0x0E/0x07)")
        try:
            try:
                self.client.wait_for_push(ParameterPush, PUSH_WAIT_S)
            except GimbalTimeoutError:
                return Check("push", False, f"no parameter push within {PUSH_WAIT_S:g} s of enabling it",
                             "firmware that does not push, or pushes on another id", {"hz": 0.0})
            before = self.census.snapshot()["pushes"]
            time.sleep(window)
            hz = (self.census.snapshot()["pushes"] - before) / window
        finally:
            if not was_on:
                try:
                    self.client.set_push(False)
                except GimbalError:
                    pass  # left on: harmless, and said by the next run's listen
        summary = f"parameter push {hz:.1f} Hz"
        if hz < MIN_PUSH_HZ:
            return Check("push", False, summary, f"below {MIN_PUSH_HZ:g} Hz: pushes lost (bus load, "
                         "termination) or a slow adapter", {"hz": hz})
        return Check("push", True, summary, data={"hz": hz})

    def camera(self) -> Check:
        try:
            recording = self.client.camera_status()
        except ReturnCodeError as exc:
            return Check("camera", False, f"camera status refused: {exc}",
                         "no camera under the gimbal's control (camera control cable or Bluetooth "
                         "pairing); needed only for track --record (doctor --no-camera skips this)")
        except GimbalError as exc:
            return Check("camera", False, f"camera status: {exc}", "the gimbal answers other queries: "
                         "replies lost (see latency)")
        return Check("camera", True, f"camera control: {'recording' if recording else 'idle'}",
                     data={"recording": recording})

    def integrity(self) -> Check:
        """Damaged packets from the gimbal over the whole run."""
        damaged = self.census.tables()[2]
        data = {"damaged": dict(damaged)}
        if damaged:
            reasons = ", ".join(f"{n} {r}" for r, n in damaged.most_common())
            return Check("integrity", False, f"damaged bytes from the gimbal: {reasons}",
                         "noise or bit errors: termination (120 Ω at the adapter), GND, cable length, "
                         "a bitrate near but not at 1 Mbit/s", data)
        packets = self.census.snapshot()["gimbal_packets"]
        return Check("integrity", True, f"{packets} packets from the gimbal, none damaged", data=data)

    def other_controller(self) -> Check:
        """Red when another host sends commands that move the gimbal or take it over; its queries
        (a monitoring tool's) are only reported."""
        frames = self.census.snapshot()["other_host_frames"]
        seen = self.client.other_hosts.seen()
        packets, control, names = seen.commands, seen.control, seen.describe()
        data = {"frames": frames, "packets": packets, "control": control, "commands": dict(seen.names)}
        if control:
            return Check("controller", False, f"{packets} DJI R SDK commands ({names or 'none whole'}; "
                         f"{frames} frames) on {_hex(self.rig.tx_id)} that this run did not send",
                         "another host drives this gimbal (another gimbaltrack, a script, a second "
                         "adapter): stop it, two controllers fight", data)
        if frames:
            return Check("controller", True, f"another host sends on {_hex(self.rig.tx_id)}, but no control "
                         f"commands: {names or 'no whole packet'} ({frames} frames)", data=data)
        return Check("controller", True, f"no other host sends on {_hex(self.rig.tx_id)}", data=data)

    # -- moving (only with --wiggle) -----------------------------------------------------

    def wiggle(self) -> list[Check]:
        """Position steps of ``WIGGLE_DEG`` on yaw and pitch and back, then a short speed nudge on
        each, always returned to the start and released. The attitude is read from the parameter
        push, whose layout has no firmware variants, so a legacy reply's axis order is checked
        against it."""
        was_on = self.census.snapshot()["pushes"] > 0
        self.client.set_push(True)
        start = self._attitude()
        checks = []
        try:
            for axis in ("yaw", "pitch"):
                checks.append(self._follow(axis, start))
                if axis == "pitch" and self.census.snapshot()["legacy_replies"]:
                    checks.append(self._legacy_order())
                self._move_to(start.yaw, start.pitch)
            for axis in ("yaw", "pitch"):
                checks.append(self._nudge(axis))
                self._move_to(start.yaw, start.pitch)
        finally:
            with _still_sending():
                self.client.stop_and_release()
                self._move_to(start.yaw, start.pitch)
                if not was_on:
                    self.client.set_push(False)
        return checks

    def _attitude(self) -> AxisDegrees:
        """The attitude of the next parameter push (degrees, as the gimbal reports it)."""
        attitude = self.client.wait_for_push(ParameterPush, PUSH_WAIT_S)[0].attitude
        if attitude is None:
            raise GimbalError("the parameter push carries no attitude")
        return attitude

    def _move_to(self, yaw: float, pitch: float) -> None:
        self.client.request(position_message(yaw, 0.0, pitch, time_s=WIGGLE_TIME_S, axes=("yaw", "pitch")))
        time.sleep(WIGGLE_TIME_S + SETTLE_S)

    def _follow(self, axis: str, start: AxisDegrees) -> Check:
        step = wiggle_step(axis, getattr(start, axis))
        target = {"yaw": start.yaw, "pitch": start.pitch}
        target[axis] += step
        try:
            self._move_to(target["yaw"], target["pitch"])
        except ReturnCodeError as exc:
            return Check(f"{axis} follows", False, f"{axis} to {step:+g}° by position control refused: {exc}",
                         "a user angle limit, motors off, or calibrating")
        moved = getattr(self._attitude(), axis) - getattr(start, axis)
        summary = f"{axis} to {step:+g}° by position control: the attitude moved {moved:+.1f}°"
        data = {"commanded": step, "moved": round(moved, 2)}
        if abs(moved - step) <= FOLLOW_TOLERANCE_DEG:
            return Check(f"{axis} follows", True, summary, data=data)
        if abs(moved) < FOLLOW_TOLERANCE_DEG:
            hint = "the axis did not move: motors off, locked, at a limit, or an unbalanced payload"
        else:
            hint = "the attitude does not follow the command: an unbalanced payload or a limit"
        return Check(f"{axis} follows", False, summary, hint, data)

    def _legacy_order(self) -> Check:
        """With pitch moved away from roll, the legacy angle reply, read in the configured order,
        must agree with the push."""
        reply = self.client.get_angles("attitude")
        pushed = self._attitude()
        summary = (f"legacy angles read with --legacy-order {self.rig.legacy_order}: pitch {reply.pitch:+.1f}°, "
                   f"the push says {pushed.pitch:+.1f}°")
        if abs(reply.pitch - pushed.pitch) <= abs(reply.pitch - pushed.roll):
            return Check("legacy order", True, summary)
        other = LEGACY_ORDER_YPR if self.rig.legacy_order == LEGACY_ORDER_DOCUMENT else LEGACY_ORDER_DOCUMENT
        return Check("legacy order", False, summary, f"roll and pitch swapped: use --legacy-order {other}")

    def _nudge(self, axis: str) -> Check:
        """``NUDGE_DPS`` in this project's positive direction (right, up) through the configured
        signs, for ``NUDGE_S``: the attitude, read through the attitude signs, must grow."""
        sign = self.rig.yaw_sign if axis == "yaw" else self.rig.pitch_sign
        attitude_sign = self.rig.yaw_attitude_sign if axis == "yaw" else self.rig.pitch_attitude_sign
        before = getattr(self._attitude(), axis) * attitude_sign
        speed = {"yaw": 0.0, "pitch": 0.0, axis: NUDGE_DPS * sign}
        try:
            end = time.monotonic() + NUDGE_S
            while time.monotonic() < end:
                self.client.speed(speed["yaw"], speed["pitch"])
                time.sleep(0.1)
        finally:
            with _still_sending():
                self.client.stop_and_release()
        time.sleep(SETTLE_S)
        moved = getattr(self._attitude(), axis) * attitude_sign - before
        flags = f"--invert-{axis}" + (" on" if sign < 0 else " off") + f", --invert-{axis}-attitude" + \
            (" on" if attitude_sign < 0 else " off")
        summary = f"{axis} speed {NUDGE_DPS:+g}°/s ({flags}): the attitude moved {moved:+.1f}°"
        data = {"moved": round(moved, 2)}
        if moved > FOLLOW_TOLERANCE_DEG:
            return Check(f"{axis} sign", True, summary, data=data)
        if moved < -FOLLOW_TOLERANCE_DEG:
            return Check(f"{axis} sign", False, summary,
                         f"the sign is reversed: if the camera turned {'right' if axis == 'yaw' else 'up'}, "
                         f"toggle --invert-{axis}-attitude; if it turned the other way, toggle --invert-{axis}",
                         data)
        return Check(f"{axis} sign", False, summary, "the axis did not move under speed control", data)


def wiggle_step(axis: str, angle: float) -> float:
    """``WIGGLE_DEG`` up, or down when up would leave the document's range for ``axis``."""
    low, high = (limit / TENTHS for limit in ANGLE_RANGES[axis])
    return WIGGLE_DEG if angle + WIGGLE_DEG <= high or angle - WIGGLE_DEG < low else -WIGGLE_DEG


@contextmanager
def _still_sending() -> Iterator[None]:
    """For the moves and stops in ``finally``: a failure there must not hide the one that got us
    there; what can be sent is sent."""
    try:
        yield
    except GimbalError:
        pass


def _percentile(values: list[float], q: float) -> float:
    if len(values) == 1:
        return values[0]
    return statistics.quantiles(values, n=100, method="inclusive")[int(q) - 1]
