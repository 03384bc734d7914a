"""``gimbaltrack gimbal <command>``: every DJI R SDK command from the shell.

Angles are degrees, speeds °/s. Values are checked before anything is sent; ``--print-packet``
prints the encoded packet(s) as hex and sends nothing (no bus needed).
"""
from __future__ import annotations

import argparse
import json
import queue
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from gimbal.client import (ANGLE_KINDS, FOCUS_CALIBRATIONS, FOLLOW_MODES, ORIENTATIONS, GimbalClient,
                           lookup, position_message, speed_message)
from gimbal.errors import GimbalError, GimbalTimeoutError, RangeError
from gimbal.keepalive import MAX_RATE_HZ, MIN_RATE_HZ
from gimbal.matcher import FIRST_SEQ
from gimbal.messages import Message, message_packet
from gimbal.messages.camera import CameraAction, CameraActionCode, CameraStatusQuery
from gimbal.messages.external import (FOCUS_CALIBRATION_STATES, DialPush, FocusCalibration,
                                      FocusPositionControl, FocusPositionQuery, JoystickPush)
from gimbal.messages.limits import (ANGLE_RANGES, DIAL_RANGE, FOCUS_POSITION_RANGE, JOYSTICK_RANGE,
                                    LIMIT_RANGES, MAX_SPEED_DPS, SPEED_RANGE, STIFFNESS_RANGES, TIME_RANGE)
from gimbal.messages.motion import AXES, GetAngles, PositionControl, SpeedControl, from_raw, to_raw
from gimbal.messages.settings import (ActiveTrack, GetAngleLimits, GetMotorStiffness,
                                      RecenterSelfie, SetAngleLimits, SetFollowMode,
                                      SetMotorStiffness, SetWorkMode, SELFIE)
from gimbal.messages.telemetry import (PUSH_DISABLE, PUSH_ENABLE, ParameterPush, PushControl,
                                       VersionPush, VersionQuery)
from gimbal.messages.tlv_params import (CALIBRATION_STATES, ROLL360_MODES, AutoCalibration, CalibrationStatusPush,
                                        GetUserParams, SetUserParams, Tlv, autotune,
                                        describe_user_param, motors_off, param_table, roll360_mode)
from gimbal.packet import REPLY_OPTIONAL, encode_packet
from gimbal.session import MAX_TIMEOUT
from gimbal.values import shown
from pipelines.cli.bus import open_host_bus
from pipelines.cli.common import (CliError, add_bus_options, parse_int, parse_seconds,
                                  suppress_defaults)
from pipelines.cli.firmware_opts import add_legacy_order_option
from pipelines.cli.process import hold_on_devnull

Result = dict[str, Any]
LIMITS = tuple(LIMIT_RANGES)
STIFFNESS = ("pitch", "roll", "yaw")
CAMERA_ACTIONS = {code.name.lower().replace("_", "-"): code for code in CameraActionCode}
OK: Result = {"ok": True}
STREAM_HZ = 20.0  # joystick and dial pushes are repeated at this rate for --duration
WATCH_STALL_S = 1.0  # watch says so once when no push came for this long (gimbals push at ~50 Hz)


@dataclass
class Command:
    """One ``gimbal`` subcommand: what it would send (checked, for --print-packet) and how it
    runs against a client, returning a JSON-friendly result."""

    name: str
    help: str
    messages: Callable[[argparse.Namespace], list[Message]]
    run: Callable[[GimbalClient, argparse.Namespace], Result | None]  # None: it printed its own output
    arguments: Callable[[argparse.ArgumentParser], None] = lambda parser: None
    cmd_types: dict[type[Message], int] = field(default_factory=dict)


# -- helpers ---------------------------------------------------------------------------------

def _span(limits: tuple[int, int], unit: Callable[[int], float] = float) -> str:
    """A document range for help text, e.g. ``-180..180`` (``unit`` converts from wire units)."""
    return f"{unit(limits[0]):g}..{unit(limits[1]):g}"


def _angles(client: GimbalClient, kind: str) -> Result:
    angles = client.get_angles(kind)
    return {"yaw": angles.yaw, "roll": angles.roll, "pitch": angles.pitch}


def _kinds(args: argparse.Namespace) -> list[str]:
    return ["attitude", "joint"] if args.kind == "both" else [args.kind]


def _given(args: argparse.Namespace, names: tuple[str, ...]) -> dict[str, int]:
    return {n: getattr(args, n) for n in names if getattr(args, n) is not None}


def _for_print(args: argparse.Namespace, names: tuple[str, ...], what: str) -> None:
    given = _given(args, names)
    if args.print_packet and given and len(given) != len(names):
        raise CliError(f"--print-packet with {what} needs all of "
                       + ", ".join("--" + n.replace("_", "-") for n in names))


def _repeat(send: Callable[[], None], stop: Callable[[], None], duration: float) -> None:
    """Send a push at STREAM_HZ for ``duration`` s, then its zero, even when interrupted or when
    the bus fails (``stop`` is best effort)."""
    end = time.monotonic() + duration
    try:
        while True:
            send()
            remaining = end - time.monotonic()
            if remaining <= 0:
                break
            time.sleep(min(1 / STREAM_HZ, remaining))
    finally:
        stop()


def describe_push(message: Message, t: float) -> Result:
    """A device push as readable values (angles in degrees)."""
    out: Result = {"t": round(t, 4), "push": message.NAME}
    if isinstance(message, ParameterPush):
        if message.attitude is not None:
            out["attitude"] = message.attitude._asdict()
        if message.joint is not None:
            out["joint"] = message.joint._asdict()
        if message.limits_valid:
            out["limits"] = signed_limits({n: getattr(message, n) for n in LIMITS})
        if message.stiffness_valid:
            out["stiffness"] = {a: getattr(message, f"{a}_stiffness") for a in STIFFNESS}
    elif isinstance(message, CalibrationStatusPush):
        out.update(state=CALIBRATION_STATES.get(message.state, message.state), progress=message.progress)
    else:
        out.update(message.fields())
    return out


def render(result: Any, indent: str = "") -> str:
    """Readable text for a result: nested mappings as indented ``key: value`` lines."""
    if not isinstance(result, dict):
        return f"{indent}{result}"
    lines = []
    for key, value in result.items():
        if isinstance(value, dict):
            inline = all(not isinstance(v, dict) for v in value.values())
            if inline:
                lines.append(f"{indent}{key}: " + "  ".join(f"{k} {v}" for k, v in value.items()))
            else:
                lines.append(f"{indent}{key}:")
                lines.append(render(value, indent + "  "))
        else:
            lines.append(f"{indent}{key}: {value}")
    return "\n".join(lines)


# -- commands --------------------------------------------------------------------------------

def _angles_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--kind", choices=("attitude", "joint", "both"), default="both",
                   help="attitude (world frame) or joint (motor) angles (default: both)")


def _angles_messages(args: argparse.Namespace) -> list[Message]:
    return [GetAngles(ANGLE_KINDS[k]) for k in _kinds(args)]


def _move_args(p: argparse.ArgumentParser) -> None:
    for axis, (low, high) in ANGLE_RANGES.items():
        p.add_argument(f"--{axis}", type=float,
                       help=f"{axis} in degrees ({_span((low, high), from_raw)}); omitted axes stay")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--absolute", dest="absolute", action="store_true", default=True,
                      help="angles are absolute (default)")
    mode.add_argument("--relative", dest="absolute", action="store_false", help="angles are offsets")
    p.add_argument("--time", type=float, default=2.0,
                   help=f"seconds to get there, {_span(TIME_RANGE, from_raw)} (default 2)")


def _check_field(option: str, value: float, message: type[Message], field: str, raw_range: tuple[int, int]) -> None:
    """``CliError`` naming ``--option`` unless ``value`` (degrees, °/s or s) fits ``field`` of the
    document's ``message``; a number too large for the wire at all (1e308) is told in the
    document's units."""
    step, unit = message.UNITS[field]
    try:
        raw = to_raw(value, option)
    except RangeError:
        low, high = raw_range
        raise CliError(f"--{option} {shown(value)} is outside the document's {low * step:g}..{high * step:g}"
                       f"{unit}") from None
    try:
        message(**{field: raw}).validate()
    except RangeError as exc:
        raise CliError(f"--{option}: {exc}") from None


def _move_message(args: argparse.Namespace) -> list[Message]:
    axes = [a for a in AXES if getattr(args, a) is not None]
    if not axes:
        raise CliError("give at least one of --yaw, --roll, --pitch")
    for axis in axes:
        _check_field(axis, getattr(args, axis), PositionControl, f"{axis}_angle", ANGLE_RANGES[axis])
    _check_field("time", args.time, PositionControl, "time_for_action", TIME_RANGE)
    return [position_message(args.yaw or 0.0, args.roll or 0.0, args.pitch or 0.0,
                             absolute=args.absolute, time_s=args.time, axes=axes)]


def _move(client: GimbalClient, args: argparse.Namespace) -> Result:
    axes = [a for a in AXES if getattr(args, a) is not None]
    client.position(args.yaw or 0.0, args.roll or 0.0, args.pitch or 0.0,
                    absolute=args.absolute, time_s=args.time, axes=axes)
    return {"moving": {a: getattr(args, a) for a in axes}, "absolute": args.absolute,
            "time_s": args.time}


def _speed_messages(args: argparse.Namespace) -> list[Message]:
    for axis in ("yaw", "pitch", "roll"):
        _check_field(axis, getattr(args, axis), SpeedControl, f"{axis}_speed", SPEED_RANGE)
    return [speed_message(args.yaw, args.pitch, args.roll)]


def _speed_args(p: argparse.ArgumentParser) -> None:
    for axis in ("yaw", "pitch", "roll"):
        p.add_argument(f"--{axis}", type=float, default=0.0,
                       help=f"{axis} speed in °/s ({-MAX_SPEED_DPS:g}..{MAX_SPEED_DPS:g})")
    p.add_argument("--duration", type=parse_seconds, default=1.0, help="seconds to keep turning (default 1)")
    p.add_argument("--rate", type=float, default=25.0,
                   help=f"keep-alive rate in Hz, {MIN_RATE_HZ:g} to {MAX_RATE_HZ:g} (default 25)")


def _speed(client: GimbalClient, args: argparse.Namespace) -> Result:
    try:
        streamer = client.speed_streamer(rate_hz=args.rate)
    except ValueError as exc:
        raise CliError(str(exc)) from None
    end = time.monotonic() + args.duration
    try:
        while (remaining := end - time.monotonic()) > 0:
            streamer.set(args.yaw, args.pitch, args.roll)
            time.sleep(min(0.1, remaining))
    finally:
        streamer.stop()
    stats = streamer.stats
    if stats["reply_errors"] or (stats["reply_timeouts"] and not (stats["replies"] or stats["late_replies"])):
        failed = " and ".join(f"{what} {stats[key]}" for what, key in (("refused", "reply_errors"),
                                                                     ("did not answer", "reply_timeouts"))
                              if stats[key])
        raise CliError(f"the gimbal {failed} of {stats['sent']} speed commands", exit_code=1)
    counts = ("sent", "reply_errors", "reply_timeouts", "late_replies")
    return {"duration_s": args.duration, **{k: stats[k] for k in counts}}


def _limit_degrees(name: str) -> tuple[int, int]:
    """A limit's range in signed degrees: the document's min limits (pitch_min 0..55) say how far
    below zero the limit lies, so the user's -55..0 (and the wire's 55..0)."""
    high = LIMIT_RANGES[name][1]
    return (-high, 0) if name.endswith("_min") else (0, high)


def signed_limits(values: dict[str, int | None]) -> dict[str, int | None]:
    """Limits as the document encodes them -> signed degrees (pitch_min 55 -> -55)."""
    return {n: -v if n.endswith("_min") and v else v for n, v in values.items()}


def _limits_given(args: argparse.Namespace) -> dict[str, int]:
    """The limits given, in signed degrees, checked and encoded as the document wants them."""
    given = {}
    for name, value in _given(args, LIMITS).items():
        low, high = _limit_degrees(name)
        if not low <= value <= high:
            raise CliError(f"--{name.replace('_', '-')} {shown(value)} is outside the document's {low}..{high}°"
                           + (" (a limit below zero)" if low < 0 else ""))
        given[name] = abs(value)
    return given


def _limits_args(p: argparse.ArgumentParser) -> None:
    for name in LIMITS:
        low, high = _limit_degrees(name)
        p.add_argument("--" + name.replace("_", "-"), type=int, dest=name,
                       help=f"whole degrees {low}..{high}" + (" (below zero)" if low < 0 else ""))


def _limits_messages(args: argparse.Namespace) -> list[Message]:
    given = _limits_given(args)
    _for_print(args, LIMITS, "limits")
    return [SetAngleLimits(1, **given)] if given else [GetAngleLimits()]


def _read_or_update(given: dict[str, int], names: tuple[str, ...], field: str,
                    read: Callable[[], Message], write: Callable[..., None]) -> dict[str, int]:
    """All values read; or the ``given`` ones written, the others first read back and kept.
    ``field`` turns a name into the reply's field name."""
    if given:
        current = read() if len(given) < len(names) else None
        values = {n: given.get(n, getattr(current, field.format(n), None)) for n in names}
        write(**values)
        return values
    reply = read()
    return {n: getattr(reply, field.format(n)) for n in names}


def _limits(client: GimbalClient, args: argparse.Namespace) -> Result:
    return {"limits": signed_limits(_read_or_update(_limits_given(args), LIMITS, "{}", client.get_angle_limits,
                                                    client.set_angle_limits))}


def _stiffness_args(p: argparse.ArgumentParser) -> None:
    for axis in STIFFNESS:
        p.add_argument(f"--{axis}", type=int,
                       help=f"{axis} motor stiffness {_span(STIFFNESS_RANGES[f'{axis}_stiffness'])}")


def _stiffness_messages(args: argparse.Namespace) -> list[Message]:
    _for_print(args, STIFFNESS, "stiffness")
    given = _given(args, STIFFNESS)
    if not given:
        return [GetMotorStiffness()]
    return [SetMotorStiffness(1, **{f"{a}_stiffness": v for a, v in given.items()})]


def _stiffness(client: GimbalClient, args: argparse.Namespace) -> Result:
    return {"stiffness": _read_or_update(_given(args, STIFFNESS), STIFFNESS, "{}_stiffness", client.get_stiffness,
                                         client.set_stiffness)}


def _watch_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--duration", type=parse_seconds, help="stop after this many seconds (default: Ctrl-C)")
    p.add_argument("--no-enable", action="store_true", help="do not send 'push on' first")


def _watch(client: GimbalClient, args: argparse.Namespace) -> None:
    arrived: queue.Queue[tuple[Message, float]] = queue.Queue()
    start = time.monotonic()  # before subscribing: a push may arrive before set_push returns
    for cls in (ParameterPush, CalibrationStatusPush):
        client.on_push(cls, lambda message, t: arrived.put((message, t)))
    if not args.no_enable:
        client.set_push(True)
    end = None if args.duration is None else start + args.duration
    pushes, last, stalled = 0, start, False
    try:
        while end is None or time.monotonic() < end:
            try:
                message, t = arrived.get(timeout=0.1)
            except queue.Empty:
                if not client.alive:
                    raise CliError("the CAN bus went away", exit_code=1) from None
                if not stalled and time.monotonic() - last > WATCH_STALL_S:  # said once per silence
                    print(f"gimbaltrack gimbal: no push for {WATCH_STALL_S:g} s{_no_push_hint(args)}",
                          file=sys.stderr, flush=True)
                    stalled = True
                continue
            pushes, last, stalled = pushes + 1, t, False
            described = describe_push(message, t - start)
            print(json.dumps(described) if args.json else render(described).replace("\n", "  "),
                  flush=True)
    except KeyboardInterrupt:
        return None
    except BrokenPipeError:  # e.g. piped into head: stop quietly
        hold_on_devnull(sys.stdout.fileno())
        return None
    if not pushes:
        raise CliError(f"no push arrived in {args.duration:g} s{_no_push_hint(args)}", exit_code=1)
    return None


def _no_push_hint(args: argparse.Namespace) -> str:
    """Why a gimbal may not push, for the notes of ``watch``."""
    return " (--no-enable: its push may be off)" if args.no_enable else " (is the gimbal on, and its push on?)"


def _version_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--device-id", type=parse_int, default=1,
                   help="device ID (section 2.3.3): 1 DJI R SDK (default), 2 remote controller; 0 is reserved")
    p.add_argument("--announce", type=parse_int, metavar="VERSION",
                   help="instead of asking, announce this device's version (0xAABBCCDD) to the gimbal")


def _version_messages(args: argparse.Namespace) -> list[Message]:
    if args.announce is not None:
        return [VersionPush(args.device_id, args.announce)]
    return [VersionQuery(args.device_id)]


def _version(client: GimbalClient, args: argparse.Namespace) -> Result:
    if args.announce is not None:
        client.push_version(args.device_id, args.announce)
        return {"announced": f"0x{args.announce:08X}"}
    reply = client.version(args.device_id)
    return {"device_id": reply.device_id, "version": reply.version_text}


def _user_params_args(p: argparse.ArgumentParser) -> None:
    motors = p.add_mutually_exclusive_group()
    motors.add_argument("--motors-off", dest="motors_off", action="store_const", const=True,
                        help="turn the motors off (parameter 0x23, bit 0 set)")
    motors.add_argument("--motors-on", dest="motors_off", action="store_const", const=False,
                        help="turn the motors back on (parameter 0x23, bit 0 clear)")
    p.add_argument("--roll360-mode", choices=list(ROLL360_MODES.values()),
                   help="parameter 0x22, bits 3..5: normal three-axis (0), two-axis (1), roll 360 (2), "
                   "3D roll 360 (3)")
    p.add_argument("--param-table", type=int, help="parameter table 0..2")


def _user_params_tlvs(args: argparse.Namespace) -> list[Tlv]:
    tlvs = []
    if args.param_table is not None:
        tlvs.append(param_table(args.param_table))
    if args.roll360_mode is not None:
        tlvs.append(roll360_mode(next(k for k, v in ROLL360_MODES.items() if v == args.roll360_mode)))
    if args.motors_off is not None:
        tlvs.append(motors_off(args.motors_off))
    return tlvs


def _user_params_messages(args: argparse.Namespace) -> list[Message]:
    tlvs = _user_params_tlvs(args)
    return [SetUserParams(tuple(tlvs))] if tlvs else [GetUserParams()]


def _described(tlvs: tuple[Tlv, ...]) -> Result:
    out: Result = {}
    for tlv in tlvs:
        out.update(describe_user_param(tlv))
    return out


def _user_params(client: GimbalClient, args: argparse.Namespace) -> Result:
    tlvs = _user_params_tlvs(args)
    if tlvs:
        return {"set": _described(client.set_user_params(tlvs))}
    return _described(client.get_user_params())


def _camera_action(name: str | None) -> Callable[[argparse.Namespace], list[Message]]:
    """The CameraAction for ``name``, or for the ``action`` argument when name is None."""
    return lambda args: [CameraAction(CAMERA_ACTIONS[name or args.action])]


def _focus_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("action", choices=("position", "calibrate", "read"),
                   help="position: absolute position push, unanswered (sub-ID 0x01); calibrate: a "
                   "calibration step (0x02); read: calibration state and position (0x15)")
    p.add_argument("value", nargs="?",
                   help=f"position {_span(FOCUS_POSITION_RANGE)}, or auto|manual|set-min|set-max|stop|none "
                   "(manual: set-min and set-max at the two ends first, then manual)")


def _focus_messages(args: argparse.Namespace) -> list[Message]:
    if args.action == "read":
        if args.value is not None:
            raise CliError("focus read takes no value")
        return [FocusPositionQuery()]
    if args.value is None:
        raise CliError(f"focus {args.action} needs a value")
    if args.action == "position":
        try:
            return [FocusPositionControl(position=int(args.value, 0))]
        except ValueError:
            raise CliError(f"focus position must be an integer {_span(FOCUS_POSITION_RANGE)}, "
                           f"not {args.value!r}") from None
    return [FocusCalibration(calibration_cmd=lookup(FOCUS_CALIBRATIONS, args.value,
                                                    "focus calibration command"))]


def _focus(client: GimbalClient, args: argparse.Namespace) -> Result:
    message = _focus_messages(args)[0]
    if isinstance(message, FocusPositionControl):
        client.focus_position(message.position)
        return {"position": message.position}
    if isinstance(message, FocusCalibration):
        if not client.focus_calibration(args.value):
            raise CliError(f"focus calibration {args.value}: the focus motor reports it failed "
                           "(execution result 0x01)", exit_code=1)
        return {"calibration": args.value, "succeeded": True}
    reply = client.focus_read()
    return {"calibration_state": FOCUS_CALIBRATION_STATES.get(reply.calibration_state, reply.calibration_state),
            "position": reply.position}


def _joystick_args(p: argparse.ArgumentParser) -> None:
    for axis in ("yaw", "pitch", "roll"):
        p.add_argument(f"--{axis}", type=int, default=0, help=f"{axis} stick, raw {_span(JOYSTICK_RANGE)}")
    p.add_argument("--duration", type=parse_seconds, default=0.5,
                   help=f"seconds to hold it (sent at {STREAM_HZ:g} Hz, then centred; default 0.5)")


def _dial_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("speed", type=int, help=f"dial speed, raw {_span(DIAL_RANGE)}")
    p.add_argument("--duration", type=parse_seconds, default=0.5,
                   help=f"seconds to hold it (sent at {STREAM_HZ:g} Hz, then zeroed; default 0.5)")


def _ok(action: Callable[[GimbalClient, argparse.Namespace], Any]) -> Callable[[GimbalClient, argparse.Namespace], Result]:
    def run(client: GimbalClient, args: argparse.Namespace) -> Result:
        action(client, args)
        return dict(OK)
    return run


def _choice_arg(name: str, choices: list[str], help_text: str) -> Callable[[argparse.ArgumentParser], None]:
    return lambda p: p.add_argument(name, choices=choices, help=help_text)


COMMANDS = [
    Command("angles", "read attitude and joint angles (degrees)", _angles_messages,
            lambda c, a: {k: _angles(c, k) for k in _kinds(a)}, _angles_args),
    Command("move", "position control: go to (or by) angles in degrees", _move_message, _move,
            _move_args),
    Command("speed", "turn at °/s for --duration, kept alive, then stop and release", _speed_messages, _speed,
            _speed_args),
    Command("limits", "read the angle limits, or set them (unset ones are kept)", _limits_messages,
            _limits, _limits_args),
    Command("stiffness", "read motor stiffness, or set it (unset axes are kept)",
            _stiffness_messages, _stiffness, _stiffness_args),
    Command("push", "turn the parameter push on or off",
            lambda a: [PushControl(PUSH_ENABLE if a.state == "on" else PUSH_DISABLE)],
            _ok(lambda c, a: c.set_push(a.state == "on")),
            _choice_arg("state", ["on", "off"], "on: the gimbal pushes attitude, joint angles, limits and "
                        "stiffness (0x0E/0x08); off: it stops")),
    Command("watch", "print pushes as they arrive, until Ctrl-C or --duration",
            lambda a: [] if a.no_enable else [PushControl(PUSH_ENABLE)], _watch, _watch_args),
    Command("version", "read a module's version (or --announce one)", _version_messages, _version,
            _version_args),
    Command("user-params", "read user parameters, or set them", _user_params_messages,
            _user_params, _user_params_args),
    Command("mode", "landscape/portrait orientation",
            lambda a: [SetWorkMode(orientation=ORIENTATIONS[a.orientation])],
            _ok(lambda c, a: c.set_work_mode(a.orientation)),
            _choice_arg("orientation", list(ORIENTATIONS),
                        "keep: no change; landscape: 0 deg about the X axis; landscape-flipped: 180 deg; "
                        "portrait: 90 deg; portrait-flipped: -90 deg; toggle: landscape <-> portrait, the "
                        "gimbal picks the angle; default: back to the default mode")),
    Command("recenter", "recenter once", lambda a: [RecenterSelfie()], _ok(lambda c, a: c.recenter())),
    Command("selfie", "turn around for a selfie", lambda a: [RecenterSelfie(action=SELFIE)],
            _ok(lambda c, a: c.selfie())),
    Command("follow", "follow mode: lock, yaw or fpv",
            lambda a: [SetFollowMode(FOLLOW_MODES[a.mode])],
            _ok(lambda c, a: c.set_follow_mode(a.mode)),
            _choice_arg("mode", list(FOLLOW_MODES), "lock: gimbal lock (0x00); yaw: yaw follow (0x02); "
                        "fpv: the document's sport mode, 运动模式 (0x03)")),
    Command("calibrate", "start or stop auto-tuning of the control parameters",
            lambda a: [AutoCalibration((autotune(a.action == "start", 1 if a.single_pose else 0),))],
            _ok(lambda c, a: c.auto_calibration(a.action == "start", 1 if a.single_pose else 0)),
            lambda p: (p.add_argument("action", choices=["start", "stop"],
                                      help="start or stop auto-tuning (TLV 0x00, bit 0)"),
                       p.add_argument("--default-mode", dest="single_pose", action="store_false",
                                      help="default tuning instead of the single-pose mode the "
                                      "document recommends")),
            {AutoCalibration: REPLY_OPTIONAL}),
    Command("activetrack", "toggle ActiveTrack on or off", lambda a: [ActiveTrack()],
            _ok(lambda c, a: c.activetrack_toggle()), cmd_types={ActiveTrack: REPLY_OPTIONAL}),
    Command("focus", "focus motor: position N, calibrate CMD, or read", _focus_messages, _focus,
            _focus_args),
    Command("joystick", "external joystick push (raw values)",
            lambda a: [JoystickPush(pitch_speed=a.pitch, roll_speed=a.roll, yaw_speed=a.yaw)],
            _ok(lambda c, a: _repeat(lambda: c.joystick(a.yaw, a.pitch, a.roll),
                                     lambda: c.send_best_effort(JoystickPush()), a.duration)),
            _joystick_args),
    Command("dial", "external dial push (raw value)", lambda a: [DialPush(dial_speed=a.speed)],
            _ok(lambda c, a: _repeat(lambda: c.dial(a.speed), lambda: c.send_best_effort(DialPush()),
                                     a.duration)),
            _dial_args),
    Command("photo", "take a photo", _camera_action("take-photo"), _ok(lambda c, a: c.photo())),
    Command("record", "start or stop recording",
            lambda a: [CameraAction(CAMERA_ACTIONS[f"{a.action}-recording"])],
            _ok(lambda c, a: c.start_recording() if a.action == "start" else c.stop_recording()),
            _choice_arg("action", ["start", "stop"], "start (0x0003) or stop (0x0004) recording")),
    Command("camera-action", "any camera action of the document", _camera_action(None),
            _ok(lambda c, a: c.camera_action(CAMERA_ACTIONS[a.action])),
            _choice_arg("action", list(CAMERA_ACTIONS),
                        ", ".join(f"{name} (0x{code:04X})" for name, code in CAMERA_ACTIONS.items()))),
    Command("camera-status", "is the camera recording?", lambda a: [CameraStatusQuery()],
            lambda c, a: {"recording": c.camera_status()}),
]


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("gimbal", help="talk to a DJI RS gimbal: read, move, set, camera",
                                   description=__doc__.replace("``", "'"))
    _shared_options(parser)
    commands = parser.add_subparsers(dest="gimbal_command", metavar="COMMAND", required=True)
    for command in COMMANDS:
        sub = commands.add_parser(command.name, help=command.help, description=command.help)
        command.arguments(sub)
        sub.add_argument("--print-packet", action="store_true",
                         help="print the encoded packet(s) as hex and send nothing")
        sub.add_argument("--seq", type=parse_int, default=FIRST_SEQ,
                         help=f"SEQ for --print-packet (default 0x{FIRST_SEQ:04X})")
        _shared_options(sub, repeated=True)
        sub.set_defaults(func=lambda args, command=command: run(command, args))


def _shared_options(parser: argparse.ArgumentParser, repeated: bool = False) -> None:
    """Options accepted before the command (``gimbal -i sim --json angles``) and after it."""
    shared = [parser.add_argument("--json", action="store_true", help="print the result as JSON"),
              parser.add_argument("--timeout", type=float, default=0.1,
                                  help="reply timeout in s (default 0.1)")]
    add_bus_options(parser, repeated=repeated)
    add_legacy_order_option(parser, repeated=repeated)
    if repeated:
        suppress_defaults(shared)


def run(command: Command, args: argparse.Namespace) -> int:
    try:
        messages = command.messages(args)
        for message in messages:
            message.validate()
        if args.print_packet:
            if not 0 <= args.seq <= 0xFFFF:
                raise CliError(f"--seq must be 0..0xFFFF (SEQ is 2 bytes), not {shown(args.seq)}")
            for offset, message in enumerate(messages):
                packet = message_packet(message, (args.seq + offset) & 0xFFFF,
                                        command.cmd_types.get(type(message)))
                print(" ".join(f"{b:02X}" for b in encode_packet(packet)))
            return 0
        if not 0 < args.timeout <= MAX_TIMEOUT:
            raise CliError(f"--timeout must be a number of seconds above 0 (at most {MAX_TIMEOUT:.0f}), "
                           f"not {args.timeout:g}")
        with open_host_bus(args) as bus, \
                GimbalClient(bus, tx_id=args.tx_id, rx_id=args.rx_id, timeout=args.timeout,
                             legacy_attitude_order=args.legacy_order) as client:
            result = command.run(client, args)
    except RangeError as exc:
        raise CliError(str(exc)) from None
    except GimbalTimeoutError as exc:
        raise CliError(f"the gimbal did not answer: {exc}", exit_code=1) from None
    except GimbalError as exc:
        raise CliError(str(exc), exit_code=1) from None
    if result is None:
        return 0
    if args.json:
        print(json.dumps(result))
    elif result:
        print("ok" if result == OK else render(result))
    return 0
