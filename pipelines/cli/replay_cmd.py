"""``gimbaltrack replay CANLOG``: a recorded session's DJI R SDK traffic, decoded packet by packet
(``gimbal.log_decode``), with a summary; optionally the host's frames go out again onto a bus,
timestamps honoured (scaled by ``--speed``)."""
from __future__ import annotations

import argparse
import json
import sys
import time
from collections import Counter
from collections.abc import Iterator
from contextlib import closing, contextmanager
from dataclasses import dataclass, field
from typing import Any, TextIO

import can

from gimbal.client import stop_messages
from gimbal.log_decode import HOST_TO_GIMBAL, LogDecoder, Record
from gimbal.messages import message_packet
from gimbal.messages.motion import SPEED_TAKE_CONTROL, from_raw
from gimbal.transport import CanTransport, packet_frames
from gimbal.values import shown
from pipelines.cli.bus import SIM_INTERFACE, open_host_bus, simulated_gimbal
from pipelines.cli.common import CliError, add_bus_options
from pipelines.cli.firmware_opts import add_legacy_order_option
from pipelines.cli.log_input import LogFrames, check_log_path, close_reader, open_log
from pipelines.cli.sim_cmd import status_line

ARROWS = {HOST_TO_GIMBAL: "host->gimbal", None: "?"}
PUSH_KEY_FIELDS = ("yaw_angle", "roll_angle", "pitch_angle")  # a push's other fields rarely change
STOP_SEQ = 0xFFF0  # SEQs of the safety stop sent after an interrupted replay
SETTLE_S = 1.0
SPEED_RANGE = (0.1, 100.0)  # playback factors: a 10-minute log takes 100 min to 6 s  # how long the simulated gimbal may take to come to rest before its state is shown


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "replay", help="play a recorded CAN log back: decoded packets, a summary, optionally onto a bus",
        description="Play a recorded session's CAN traffic (the can.log 'gimbaltrack track' writes, or "
        "any log python-can reads) through the DJI R SDK decoder: one line per packet (time, direction, "
        "name, key fields in degrees) and a summary. With -i the host->gimbal packets are sent onto that "
        "bus at their recorded times ('-i sim': the built-in simulated gimbal, whose final state is "
        "printed); only whole packets of the document with every value in its range are sent, the "
        "others are counted in the summary. An interrupted replay onto a bus ends with zero speed "
        "and control released. A log whose last line is cut short (a recorder stopped mid-write) is "
        "replayed up to it, with a warning; one unreadable part way is summarised up to there, then "
        "the error (exit 2).",
        epilog="examples:\n  gimbaltrack replay out/track/can.log\n"
        "  gimbaltrack replay out/track/can.log --json | jq .\n"
        "  gimbaltrack replay out/track/can.log -i sim --speed 4\n"
        "  gimbaltrack replay out/track/can.log -i socketcan -c can0",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("log", help="CAN log (candump .log, .asc, .blf, .csv, .trc, .db; .gz of those)")
    parser.add_argument("--json", action="store_true",
                        help="one decode JSON object per packet, then {\"summary\": ...}")
    parser.add_argument("--realtime", action="store_true",
                        help="print at the recorded pace (always on when sending onto a bus)")
    parser.add_argument("--speed", type=float, default=1.0, metavar="X",
                        help=f"playback speed factor for --realtime and bus output, {SPEED_RANGE[0]:g} to "
                        f"{SPEED_RANGE[1]:g} (default 1)")
    add_bus_options(parser)
    add_legacy_order_option(parser)
    parser.set_defaults(func=run)


@dataclass
class ReplaySummary:
    """What the log held: packets per name, errors, the speed command stream."""

    packets: Counter[str] = field(default_factory=Counter)
    errors: Counter[str] = field(default_factory=Counter)
    out_of_range: int = 0
    speed_times: list[float] = field(default_factory=list)
    max_speed_dps: float = 0.0
    last_speed: dict[str, int] | None = None
    frames: int = 0
    frames_sent: int = 0
    not_sent: Counter[str] = field(default_factory=Counter)  # host packets held back, by reason
    echoes: int = 0  # host frames the bus looped back, skipped
    first_t: float | None = None
    last_t: float | None = None

    def add(self, record: Record) -> None:
        if "error" in record:
            self.errors[record["error"]] += 1
            return
        self.packets[record["name"]] += 1
        self.out_of_range += "out_of_range" in record
        if record["name"] == "speed_control" and record["direction"] == HOST_TO_GIMBAL:
            fields = record["fields"]
            self.last_speed = fields
            if record["timestamp"] is not None:
                self.speed_times.append(record["timestamp"])
            speeds = (fields.get(k, 0) for k in ("yaw_speed", "roll_speed", "pitch_speed"))
            self.max_speed_dps = max(self.max_speed_dps, *(abs(from_raw(v)) for v in speeds))

    @property
    def holds_control(self) -> bool:
        """True when the last speed command left the host in control (bit 7 set)."""
        return self.last_speed is not None and bool(self.last_speed.get("ctrl_byte", 0) & SPEED_TAKE_CONTROL)

    def speed_rate_hz(self) -> float | None:
        t = self.speed_times
        return (len(t) - 1) / (t[-1] - t[0]) if len(t) > 1 and t[-1] > t[0] else None

    def as_dict(self) -> dict[str, Any]:
        last = self.last_speed
        return {"frames": self.frames, "frames_sent": self.frames_sent, "packets_not_sent": dict(self.not_sent),
                "echoes_skipped": self.echoes,
                "duration_s": None if self.first_t is None else self.last_t - self.first_t,
                "packets": dict(self.packets), "errors": dict(self.errors), "out_of_range": self.out_of_range,
                "speed_commands": len(self.speed_times), "speed_rate_hz": self.speed_rate_hz(),
                "max_speed_dps": self.max_speed_dps,
                "last_speed": None if last is None else {
                    "yaw_dps": from_raw(last.get("yaw_speed", 0)),
                    "roll_dps": from_raw(last.get("roll_speed", 0)),
                    "pitch_dps": from_raw(last.get("pitch_speed", 0)),
                    "ctrl_byte": last.get("ctrl_byte"), "released": not self.holds_control}}

    def text(self) -> str:
        d = self.as_dict()
        rate = d["speed_rate_hz"]
        lines = [f"replayed {d['frames']} CAN frames over {d['duration_s'] or 0.0:.2f} s"
                 + (f", sent {d['frames_sent']} host->gimbal frames" if d["frames_sent"] else "")
                 + (f", held back {sum(self.not_sent.values())} host packets ("
                    + ", ".join(f"{n} {c}" for n, c in sorted(self.not_sent.items())) + ")"
                    if self.not_sent else "")
                 + (f" ({self.echoes} looped-back host frames skipped)" if self.echoes else ""),
                 "packets: " + (", ".join(f"{n} {c}" for n, c in sorted(self.packets.items())) or "none"),
                 f"speed commands: {d['speed_commands']}"
                 + (f" at {rate:.1f} Hz" if rate else "") + f", max |speed| {d['max_speed_dps']:.1f} deg/s",
                 "errors: " + (", ".join(f"{n} {c}" for n, c in sorted(self.errors.items())) or "none")
                 + (f"; {self.out_of_range} out of range" if self.out_of_range else "")]
        if last := d["last_speed"]:
            lines.append(f"last speed command: yaw {last['yaw_dps']:+.1f} pitch {last['pitch_dps']:+.1f} "
                         f"deg/s, control {'released' if last['released'] else 'HELD'}")
        return "\n".join(lines)


def format_record(record: Record, t0: float | None) -> str:
    """One readable line: time since the first frame, direction, name, key fields in degrees."""
    t = record.get("timestamp")
    when = f"{t - t0:10.3f}" if t is not None and t0 is not None else f"{'-':>10}"
    where = ARROWS.get(record["direction"], "gimbal->host")
    if "error" in record:
        return f"{when}  {where:<12}  ERROR {record['error']}: {record['detail']} [{record['hex']}]"
    fields = record["fields"]
    if record["kind"] == "push" and record["name"] == "parameter_push":
        fields = {k: fields[k] for k in PUSH_KEY_FIELDS if k in fields}
    text = " ".join(_field(k, v, record) for k, v in fields.items())
    flag = f"  OUT OF RANGE: {record['out_of_range']}" if "out_of_range" in record else ""
    return f"{when}  {where:<12}  {record['name']:<26} {text}{flag}".rstrip()


def _field(name: str, value: Any, record: Record) -> str:
    if isinstance(value, int) and name.endswith("_angle"):
        return f"{name.removesuffix('_angle')}={from_raw(value):+.1f}deg"
    if isinstance(value, int) and name.endswith("_speed"):
        return f"{name.removesuffix('_speed')}={from_raw(value):+.1f}deg/s"
    if name == "ctrl_byte" and isinstance(value, int):
        return f"ctrl=0x{value:02X}"
    if name == "return_code":
        return f"rc={value} ({record.get('return_code_meaning', '?')})"
    return f"{name}={value}"


#: The decoder's errors for a whole packet that does not decode (the framer's own reasons, such as
#: ``truncated`` or ``crc16``, are kept as they are).
_UNDECODABLE = {"unknown_command", "bad_payload", "unmatched_legacy_reply"}


def _send_host_packets(records: list[Record], bus: can.BusABC, tx_id: int, summary: ReplaySummary) -> None:
    """Send the host packets among the decoder's ``records`` that decoded to a message of the
    document with every value in its range (their own bytes, cut into frames as recorded); count
    the others in ``summary.not_sent`` by reason. A foreign or corrupt log thus never puts an
    out-of-range value or a broken packet on a gimbal's bus."""
    for record in records:
        if record["direction"] != HOST_TO_GIMBAL:
            continue
        if "error" in record:
            summary.not_sent["undecodable" if record["error"] in _UNDECODABLE else record["error"]] += 1
        elif "out_of_range" in record:
            summary.not_sent["out_of_range"] += 1
        else:
            summary.frames_sent += _send(bus, bytes.fromhex(record["hex"]), tx_id)


class _Pacer:
    """Sleeps until a log timestamp's turn, the log's clock scaled by ``speed``."""

    def __init__(self, speed: float) -> None:
        self.speed = speed
        self._origin: tuple[float, float] | None = None

    def wait(self, timestamp: float) -> None:
        if self._origin is None:
            self._origin = (timestamp, time.monotonic())
            return
        log_t0, wall_t0 = self._origin
        delay = wall_t0 + (timestamp - log_t0) / self.speed - time.monotonic()
        if delay > 0:
            time.sleep(delay)


@contextmanager
def _target(args: argparse.Namespace) -> Iterator[tuple[can.BusABC | None, Any]]:
    """(bus to send onto or None, simulated gimbal for '-i sim' or None)."""
    if args.interface is None:
        yield None, None
        return
    if args.interface == SIM_INTERFACE:
        with simulated_gimbal(args) as pair:
            yield pair
        return
    with open_host_bus(args) as bus:
        yield bus, None


def run(args: argparse.Namespace, out: TextIO | None = None) -> int:
    out = out or sys.stdout
    low, high = SPEED_RANGE
    if not low <= args.speed <= high:
        raise CliError(f"--speed takes a finite factor from {low:g} to {high:g}, not {shown(args.speed)}")
    if args.interface is None and (args.channel is not None or args.bitrate is not None):
        raise CliError("-c/--channel and -b/--bitrate need -i/--interface: replay sends onto a bus only with -i")
    check_log_path(args.log)  # before a bus is opened
    summary = ReplaySummary()
    failure = None
    with _target(args) as (bus, sim):
        started = time.monotonic()
        completed = False
        try:
            _replay(args, summary, bus, out)
            completed = True
        except CliError as exc:  # a log unreadable part way, a bus refusing: what was replayed is summarised first
            failure = exc
        finally:
            if bus is not None and summary.frames_sent and (not completed or summary.holds_control):
                _stop_gimbal(bus, args.tx_id, args.rx_id)
        if sim is not None:  # before the summary, which stays the last object
            state = _settled(sim)
            _print(out, args.json, {"sim_state": state.as_dict()},
                   "simulated gimbal at the end: " + status_line(state, time.monotonic() - started))
        _print(out, args.json, {"summary": summary.as_dict()}, summary.text())
    if failure is not None:
        raise failure
    return 0


def _settled(sim: Any) -> Any:
    """The simulated gimbal's state once its axes stop (they decelerate at a finite rate)."""
    deadline = time.monotonic() + SETTLE_S
    state = sim.state()
    while state.moving and time.monotonic() < deadline:
        time.sleep(0.02)
        state = sim.state()
    return state


def _replay(args: argparse.Namespace, summary: ReplaySummary, bus: can.BusABC | None, out: TextIO) -> None:
    decoder = LogDecoder(args.tx_id, args.rx_id, args.legacy_order)
    pacer = _Pacer(args.speed) if args.realtime or bus is not None else None
    skip_echoes = _marks_sent_frames(args.log, args.tx_id)
    with closing(LogFrames(args.log, "replay")) as frames:
        for frame in frames:
            if skip_echoes and frame.arbitration_id == args.tx_id and frame.is_rx:
                summary.echoes += 1
                continue
            summary.frames += 1
            summary.first_t = frame.timestamp if summary.first_t is None else summary.first_t
            summary.last_t = frame.timestamp
            if pacer is not None:
                pacer.wait(frame.timestamp)
            records = decoder.feed_frame(frame)
            if bus is not None:
                _send_host_packets(records, bus, args.tx_id, summary)
            _emit(records, summary, args.json, out)
    records = decoder.finish(summary.last_t)
    if bus is not None:  # a host packet left incomplete is counted, never sent
        _send_host_packets(records, bus, args.tx_id, summary)
    _emit(records, summary, args.json, out)
    frames.check()


def _marks_sent_frames(path: str, tx_id: int) -> bool:
    """True when the log marks the host's frames as sent (``T``): then host-id frames marked
    received are the bus's echo of them (udp_multicast loops every frame back) and are skipped."""
    reader, _ = open_log(path)
    try:
        return any(f.arbitration_id == tx_id and not f.is_rx for f in reader)
    except Exception:  # noqa: BLE001 - an unreadable log is reported by the replay itself
        return False
    finally:
        close_reader(reader)


def _send(bus: can.BusABC, raw: bytes, tx_id: int) -> int:
    """Send one packet's frames; returns how many."""
    frames = packet_frames(raw, tx_id)
    try:
        for frame in frames:
            bus.send(frame, timeout=0.05)
    except can.CanError as exc:
        raise CliError(f"the bus refused a frame: {exc}", exit_code=1) from None
    return len(frames)


def _stop_gimbal(bus: can.BusABC, tx_id: int, rx_id: int) -> None:
    """Best effort: zero speed, then zero with control released."""
    transport = CanTransport(bus, tx_id, rx_id)
    for offset, message in enumerate(stop_messages()):
        try:  # the release is tried even when the zero failed
            transport.send(message_packet(message, STOP_SEQ + offset))
        except (can.CanError, OSError) as exc:
            print(f"gimbaltrack replay: warning: could not send the stop: {exc}", file=sys.stderr)


def _emit(records: list[Record], summary: ReplaySummary, as_json: bool, out: TextIO) -> None:
    for record in records:
        summary.add(record)
        out.write(json.dumps(record) + "\n" if as_json else format_record(record, summary.first_t) + "\n")


def _print(out: TextIO, as_json: bool, obj: dict[str, Any], text: str) -> None:
    out.write(json.dumps(obj) + "\n" if as_json else text + "\n")
    out.flush()
