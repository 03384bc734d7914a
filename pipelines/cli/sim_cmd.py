"""``gimbaltrack sim``: run the simulated DJI RS gimbal on a CAN bus (e.g. udp_multicast between
processes), printing its state once a second, until Ctrl-C, SIGTERM or --duration."""
from __future__ import annotations

import argparse
import json
import math
import signal
import threading
import time
from types import FrameType

import can

from gimbal.messages.motion import AXES
from gimbal.sim import Faults, SimConfig, SimState, SimulatedGimbal
from gimbal.sim.checks import FieldError
from gimbal.sim.config import MAX_PUSH_RATE_HZ
from gimbal.sim.faults import DIRECTIONS
from gimbal.sim.slcan_pty import SlcanPty, virtual_pair
from pipelines.cli.bus import SIM_INTERFACE, bus_options, check_sim_ids, open_can_bus
from pipelines.cli.common import CliError, add_bus_options, parse_int, parse_seconds
from pipelines.cli.firmware_opts import add_legacy_order_option


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "sim", help="run the simulated DJI RS gimbal on a CAN bus",
        description="A protocol-complete simulated DJI RS gimbal: answers every DJI R SDK command on "
        "the bus like the real device, with an axis model and optional fault injection. Run it on "
        "udp_multicast and drive it from another process, e.g. "
        "'gimbaltrack sim -i udp_multicast -c 239.74.163.2'. The id options keep the host's point of "
        "view: the simulator listens on --tx-id and answers on --rx-id.")
    add_bus_options(parser, default_interface="udp_multicast", offers_sim=False)
    parser.add_argument("--slcan-pty", action="store_true",
                        help="instead of -i/-c/-b: be a USB-CAN adapter speaking SLCAN on a pseudo-terminal "
                        "whose path is printed first on standard output; drive it with '-i slcan -c PATH'")
    model = parser.add_argument_group("device")
    model.add_argument("--legacy", action="store_true", help="old firmware: replies omit CmdSet/CmdID")
    add_legacy_order_option(model)
    model.add_argument("--push-reply-bit", action="store_true",
                       help="send the parameter and calibration pushes with CmdType 0x20, as some firmware does")
    model.add_argument("--lenient", action="store_true",
                       help="answer get requests for limits, stiffness and user parameters sent without "
                       "their payload (default: refused as a parse error, 0x01)")
    model.add_argument("--push-rate", type=float, default=SimConfig.push_rate_hz, metavar="HZ",
                       help=f"parameter push rate once enabled, above 0 up to {MAX_PUSH_RATE_HZ:g} (default %(default)s)")
    model.add_argument("--accel", type=float, default=SimConfig.accel_dps2, metavar="DPS2",
                       help="axis acceleration limit in °/s² (default %(default)s)")
    model.add_argument("--base-yaw", type=float, default=SimConfig.base_yaw_deg, metavar="DEG",
                       help="attitude yaw minus joint yaw (default %(default)s)")
    model.add_argument("--yaw-continuous", action="store_true",
                       help="yaw wraps at ±180° and ignores the yaw limits (default: stops at the limits)")
    model.add_argument("--version", type=_version, default=SimConfig.version, metavar="AA.BB.CC.DD",
                       help="version answered to 0x0E/0x09 (default 02.05.00.00)")
    model.add_argument("--calibration-time", type=float, default=SimConfig.calibration_s, metavar="S",
                       help="auto-calibration duration (default %(default)s)")
    model.add_argument("--no-camera", action="store_true", help="no camera: camera commands fail (0x02)")
    model.add_argument("--flip", type=_axes, default=(), metavar="AXES",
                       help="axes (yaw,roll,pitch, comma separated) that turn the opposite way to a speed "
                       "command, while their angles keep their sign (one RS 5 does this for yaw)")
    faults = parser.add_argument_group("faults")
    faults.add_argument("--drop", type=float, default=0.0, metavar="FRACTION", help="lose CAN frames")
    faults.add_argument("--corrupt", type=float, default=0.0, metavar="FRACTION",
                        help="alter one byte of CAN frames")
    faults.add_argument("--fault-direction", choices=DIRECTIONS, default="both",
                        help="where --drop/--corrupt apply: rx (host to sim), tx or both (default)")
    faults.add_argument("--delay-ms", type=float, default=0.0, metavar="MS", help="delay every reply")
    faults.add_argument("--nack", type=float, default=0.0, metavar="FRACTION",
                        help="refuse this fraction of commands with --nack-code")
    faults.add_argument("--nack-code", type=parse_int, default=0x02, help="return code of refusals (default 0x02)")
    faults.add_argument("--silent", type=_window, metavar="START:END",
                        help="neither hear nor send between these seconds after start")
    faults.add_argument("--legacy-fraction", type=float, default=0.0, metavar="FRACTION",
                        help="send this fraction of replies in the legacy layout")
    faults.add_argument("--foreign-rate", type=float, default=0.0, metavar="HZ",
                        help="add foreign frames (0x530/0x531/0x426, 0x55 packets) at this rate")
    faults.add_argument("--seed", type=int, default=0, help="fault RNG seed (default 0)")
    run_group = parser.add_argument_group("run")
    run_group.add_argument("--duration", type=parse_seconds, metavar="S", help="stop after this many seconds")
    run_group.add_argument("--status-interval", type=float, default=1.0, metavar="S",
                           help="print the state every S seconds (default 1; 0: never)")
    run_group.add_argument("--json", action="store_true", help="print the full state as JSON lines")
    parser.set_defaults(func=run)


def _version(text: str) -> int:
    """AA.BB.CC.DD (hex bytes, the document's notation) or a plain integer."""
    parts = text.split(".")
    try:
        if len(parts) == 4:
            values = [int(p, 16) for p in parts]
            if all(0 <= v <= 0xFF for v in values):
                return int.from_bytes(bytes(values), "big")
        elif len(parts) == 1:  # SimConfig checks that it fits 32 bits
            return int(text, 0)
    except ValueError:
        pass
    raise argparse.ArgumentTypeError(f"not a version AA.BB.CC.DD or 32-bit integer: {text!r}")


def _axes(text: str) -> tuple[str, ...]:
    axes = tuple(a.strip() for a in text.split(",") if a.strip())
    if not axes or any(a not in AXES for a in axes):
        raise argparse.ArgumentTypeError(f"not a comma-separated list of {', '.join(AXES)}: {text!r}")
    return axes


def _window(text: str) -> tuple[float, float]:
    start, sep, end = text.partition(":")
    try:
        window = (float(start), float(end))
    except ValueError:
        window = None
    if not sep or window is None:  # Faults checks the numbers
        raise argparse.ArgumentTypeError(f"not a window START:END in seconds: {text!r}")
    return window


#: The library's fields (``SimConfig``/``Faults`` check every value) by the options that set them.
OPTION_OF_FIELD = {
    "SimConfig.push_rate_hz": "--push-rate", "SimConfig.accel_dps2": "--accel",
    "SimConfig.base_yaw_deg": "--base-yaw", "SimConfig.version": "--version",
    "SimConfig.calibration_s": "--calibration-time",
    "Faults.drop": "--drop", "Faults.corrupt": "--corrupt", "Faults.delay_s": "--delay-ms",
    "Faults.nack": "--nack", "Faults.nack_code": "--nack-code", "Faults.silent": "--silent",
    "Faults.legacy": "--legacy-fraction", "Faults.foreign_rate": "--foreign-rate",
}


def build(args: argparse.Namespace) -> tuple[SimConfig, Faults]:
    """The simulator's configuration and faults from the parsed options; ``CliError`` if invalid."""
    check_sim_ids(args)  # in the options' words, before SimConfig's own check of the same
    try:
        config = SimConfig(rx_id=args.tx_id, tx_id=args.rx_id, legacy=args.legacy,
                           legacy_attitude_order=args.legacy_order, push_reply_bit=args.push_reply_bit,
                           lenient=args.lenient,
                           push_rate_hz=args.push_rate, accel_dps2=args.accel, base_yaw_deg=args.base_yaw,
                           yaw_continuous=args.yaw_continuous, version=args.version,
                           calibration_s=args.calibration_time, camera_connected=not args.no_camera,
                           speed_signs=tuple(-1 if a in args.flip else 1 for a in AXES))
        faults = Faults(drop=args.drop, corrupt=args.corrupt, direction=args.fault_direction,
                        delay_s=args.delay_ms / 1000.0, nack=args.nack, nack_code=args.nack_code,
                        silent=args.silent, legacy=args.legacy_fraction, foreign_rate=args.foreign_rate,
                        seed=args.seed)
    except FieldError as exc:
        option = OPTION_OF_FIELD.get(exc.name)
        if option is None:  # a field no option sets (the ids are checked as they are parsed)
            raise CliError(str(exc)) from None
        given = getattr(args, option[2:].replace("-", "_"))  # in the option's unit (--delay-ms)
        raise CliError(f"{option} takes {exc.takes}, not {_given(given)}") from None
    if not 0 <= args.status_interval < math.inf:  # the CLI's own: NaN fails too
        raise CliError(f"--status-interval takes a finite interval, 0 s or more, not {args.status_interval:g}")
    if args.duration is not None and args.duration <= 0:
        raise CliError(f"--duration must be positive, not {args.duration}")
    return config, faults


def _given(value: float | tuple[float, float]) -> str:
    """An option's value as the user wrote it, near enough: 1e+300, nan, 999, 3:1."""
    if isinstance(value, tuple):
        return ":".join(f"{v:g}" for v in value)
    return str(value) if isinstance(value, int) else f"{value:g}"


def open_bus(args: argparse.Namespace) -> can.BusABC | None:
    """The bus the simulator answers on; None for --slcan-pty (``run`` makes that one)."""
    if args.slcan_pty:
        if args.channel is not None or args.bitrate is not None or args.interface != "udp_multicast":
            raise CliError("--slcan-pty is the bus: it takes no -i/--interface, -c/--channel or -b/--bitrate")
        return None
    if args.interface == SIM_INTERFACE:
        raise CliError("'-i sim' is the in-process simulator; give 'sim' a real bus, e.g. -i udp_multicast")
    return open_can_bus(bus_options(args))


def status_line(state: SimState, elapsed: float) -> str:
    """One short human-readable line; ``elapsed`` = seconds since start."""
    yaw, roll, pitch = state.joint
    vy, vr, vp = state.speeds
    faults = sum(state.faults.values())
    return (f"t={elapsed:.1f} joint yaw={yaw:.1f} roll={roll:.1f} pitch={pitch:.1f} "
            f"speed={vy:.1f}/{vr:.1f}/{vp:.1f} motors={'on' if state.motors_on else 'off'} "
            f"rec={'on' if state.recording else 'off'} push={'on' if state.push_enabled else 'off'} "
            f"commands={sum(state.commands.values())} faults={faults}")


def run(args: argparse.Namespace) -> int:
    config, faults = build(args)
    bus = open_bus(args)
    adapter: SlcanPty | None = None
    if bus is None:  # --slcan-pty: the gimbal on one end of a virtual bus, the adapter on the other
        adapter_bus, bus = virtual_pair()
        adapter = SlcanPty(adapter_bus).start()
        print(adapter.path, flush=True)
    stop = threading.Event()

    def on_signal(signum: int, frame: FrameType | None) -> None:
        stop.set()

    previous = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        with SimulatedGimbal(bus, config, faults) as sim:
            start = time.monotonic()
            deadline = None if args.duration is None else start + args.duration
            next_status = start + args.status_interval if args.status_interval else None
            while True:
                due = [t for t in (deadline, next_status) if t is not None]
                wait = min(max(0.0, min(due) - time.monotonic()), threading.TIMEOUT_MAX) if due else None
                if stop.wait(wait):  # at most TIMEOUT_MAX: --status-interval 1e300 overflowed
                    break
                now = time.monotonic()
                if deadline is not None and now >= deadline:
                    break
                if next_status is not None and now >= next_status:
                    state = sim.state()
                    print(json.dumps(state.as_dict()) if args.json else status_line(state, now - start),
                          flush=True)
                    next_status += args.status_interval
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
        if adapter is not None:
            adapter.stop()
            adapter.bus.shutdown()
        bus.shutdown()
    return 0
