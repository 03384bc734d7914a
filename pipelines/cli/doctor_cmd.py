"""``gimbaltrack doctor``: the bring-up check for a real rig. One line per check (✓/✗, and a hint
on failure), or ``--json``; exit 0 only when every check passed. The checks live in
``gimbal.diagnostics``."""
from __future__ import annotations

import argparse
import json
import time
from contextlib import ExitStack
from typing import Any

from gimbal.client import GimbalClient
from gimbal.diagnostics import BusCensus, Check, Doctor, RigSettings
from gimbal.errors import GimbalError
from gimbal.signals import SignalExit
from pipelines.cli.bus import SIM_INTERFACE, bus_options, load_bus_config, open_host_bus
from pipelines.cli.common import CliError, add_bus_options
from pipelines.cli.firmware_opts import add_legacy_order_option

PASSED, FAILED = "✓", "✗"


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "doctor", help="check a gimbal rig: bus, ids, replies, latency, pushes, another controller",
        description="The bring-up check for a rig: listens 1 s and counts DJI R SDK packets, foreign "
        "and error frames; asks the SDK version; detects the reply layout; measures the reply latency "
        "of 50 attitude queries and the push rate; checks camera control and that no other host "
        "commands the gimbal. With --wiggle it also moves yaw and pitch a few degrees and back and "
        "checks the sign conventions. Exit 0 only when every check passed.")
    add_bus_options(parser)
    add_legacy_order_option(parser)
    parser.add_argument("--wiggle", action="store_true",
                        help="also move yaw and pitch by 5° (position control) and nudge them at 10°/s, "
                        "then return: checks the attitude follows and the signs below hold")
    parser.add_argument("--invert-yaw", action="store_true", help="as track: a positive yaw speed turns left")
    parser.add_argument("--invert-pitch", action="store_true", help="as track: a positive pitch speed turns down")
    parser.add_argument("--invert-yaw-attitude", action="store_true",
                        help="as track: this gimbal reports its yaw with the opposite sign")
    parser.add_argument("--invert-pitch-attitude", action="store_true",
                        help="as track: this gimbal reports its pitch with the opposite sign")
    parser.add_argument("--no-camera", action="store_true",
                        help="skip the camera control check (a rig without camera control)")
    parser.add_argument("--json", action="store_true", help="one JSON object: every check and 'ok'")
    parser.set_defaults(func=run)


def rig_settings(args: argparse.Namespace) -> RigSettings:
    return RigSettings(tx_id=args.tx_id, rx_id=args.rx_id, bitrate=args.bitrate, legacy_order=args.legacy_order,
                       yaw_sign=-1 if args.invert_yaw else 1, pitch_sign=-1 if args.invert_pitch else 1,
                       yaw_attitude_sign=-1 if args.invert_yaw_attitude else 1,
                       pitch_attitude_sign=-1 if args.invert_pitch_attitude else 1,
                       camera=not args.no_camera)


def line(check: Check) -> str:
    mark = PASSED if check.ok else FAILED
    text = f"{mark} {check.name}: {check.summary}"
    return text if check.ok or not check.hint else f"{text}\n    hint: {check.hint}"


def run(args: argparse.Namespace) -> int:
    rig = rig_settings(args)
    where = "built-in simulated gimbal" if args.interface == SIM_INTERFACE else \
        " ".join(str(v) for v in (args.interface or "python-can's configured bus", args.channel) if v)
    checks: list[Check] = []
    started = time.monotonic()

    def report(check: Check) -> None:
        checks.append(check)
        if not args.json:
            print(line(check), flush=True)

    if args.interface != SIM_INTERFACE:
        load_bus_config(bus_options(args))  # a configuration naming no bus, or none: bad input (exit 2)
    try:
        with ExitStack() as stack:
            try:
                bus = stack.enter_context(open_host_bus(args))
            except CliError as exc:
                if args.interface == SIM_INTERFACE:
                    raise  # an option the simulator refuses: bad input, not a rig problem
                report(Check("bus", False, str(exc), "the adapter: plugged in, its name (-c), the "
                             "dialout group for serial ones, its driver (docs/hardware.md)"))
                return _finish(args, where, checks, started)
            census = BusCensus(args.tx_id, args.rx_id)
            try:
                client = stack.enter_context(GimbalClient(bus, tx_id=args.tx_id, rx_id=args.rx_id,
                                                          listeners=[census],
                                                          legacy_attitude_order=args.legacy_order))
            except GimbalError as exc:
                raise CliError(str(exc)) from None
            report(Check("bus", True, f"{where} open, host sends on 0x{args.tx_id:03X}, listens on "
                         f"0x{args.rx_id:03X}"))
            try:
                for check in Doctor(client, census, rig).checks(wiggle=args.wiggle):
                    report(check)
            except GimbalError as exc:  # the bus lost mid-run: what was found so far, and this
                report(Check("run", False, f"stopped: {exc}", "the bus went away: adapter unplugged or "
                             "bus-off (docs/hardware.md)"))
    except (KeyboardInterrupt, SignalExit) as exc:  # the client has stopped the gimbal by now
        if args.json:  # what was checked still goes out
            why = exc.signal_name if isinstance(exc, SignalExit) else "SIGINT"
            _finish(args, where, [*checks, Check("run", False, f"interrupted ({why})")], started)
        raise
    return _finish(args, where, checks, started)


def _finish(args: argparse.Namespace, where: str, checks: list[Check], started: float) -> int:
    """The JSON, or the closing line; the exit status: 0 only when every check passed."""
    ok = all(check.ok for check in checks)
    if args.json:
        result: dict[str, Any] = {"bus": where, "ok": ok, "seconds": round(time.monotonic() - started, 2),
                                  "checks": [c.as_dict() for c in checks]}
        print(json.dumps(result), flush=True)
    else:
        failed = sum(not c.ok for c in checks)
        print("all checks passed" if ok else f"{failed} of {len(checks)} checks failed", flush=True)
    return 0 if ok else 1
