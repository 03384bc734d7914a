"""``gimbaltrack track SOURCE``: follow a subject in video and keep it framed with the gimbal."""
from __future__ import annotations

import argparse
import json
import socket
import sys
import time
from collections.abc import Iterator
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Any

from gimbal.client import GimbalClient
from gimbal.errors import GimbalError, GimbalTimeoutError
from gimbal.keepalive import MAX_RATE_HZ, MIN_RATE_HZ
from gimbal.signals import SignalExit, deferred_signals
from gimbal.values import shown
from gimbal.watchdog import DEFAULT_TIMEOUT_S, DEGRADED_SILENCE_S
from pipelines.cli.batch_options import add_batch_options, batch_jobs
from pipelines.cli.bus import SIM_INTERFACE, choose_track_bus, open_host_bus
from pipelines.cli.common import EXIT_INTERRUPTED, CliError, add_bus_options, existing_dir, make_out_dir, out_dir
from pipelines.cli.firmware_opts import add_legacy_order_option
from pipelines.cli.sim_faults import parse_sim_faults
from pipelines.cli.track_batch import run_track_batch
from pipelines.control.controller import ControlConfig, controller_names
from pipelines.control.limits import PROTOCOL_MAX_SPEED_DPS
from pipelines.loop.acquire import PICKS, check_roi_in_frame, parse_roi
from pipelines.loop.link import link_degraded, link_report
from pipelines.loop.track_session import DEFAULT_VIDEO_WIDTH, FEEDBACK_MODES, TrackOptions, TrackSession, make_subject
from pipelines.outputs.can_log import CanLogWriter
from pipelines.sources import FrameSource, SourceError, open_source
from tracker import SubjectTracker, available_trackers
from tracker.runtime.registry import DEFAULT_BACKEND, FALLBACK_BACKEND
from tracker.detectors import Detector

DEFAULT_DETECTOR = "motion"
LISTEN_S = 0.5  # before taking control: another controller streams at 4 Hz at the least (two commands a 0.5 s)
EXIT_DEGRADED_LINK = 3
EXIT_OTHER_CONTROLLER = 4
FPS_RANGE = (0.1, 1000.0)  # a frame every 10 s to 1000 a second; the video writer takes these


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "track", help="track a subject in video and keep it framed with the gimbal",
        description="Track a subject in a video file, image folder, camera or stream, turn its "
        "position into yaw/pitch rates (Kalman + PID) and stream them to the gimbal. With no -i, "
        "python-can's configuration (CAN_INTERFACE, CAN_CHANNEL, CAN_BITRATE, CAN_CONFIG, ~/.canrc) "
        "picks the bus when it names an interface, else the built-in simulated gimbal is used; a "
        "line on stderr says which. Outputs (annotated video, telemetry, CAN "
        "log, summary, plot) are written to --out as the run goes.",
        epilog="examples:\n  gimbaltrack track samples/demo.mp4 --roi 138,152,64,96\n"
        "  gimbaltrack track 0 --detect face -i socketcan -c can0 --record\n"
        "  gimbaltrack track udp://127.0.0.1:5000 --detect person\n"
        "  gimbaltrack track clip.mp4 --detect face --realtime   (a file at its own frame rate)\n"
        "  gimbaltrack track a.mp4 b.mp4 c.mp4 --jobs 2 --out out/batch   (out/batch/a/, out/batch/b/, ...)\n\n"
        "outputs in --out: annotated.avi, telemetry.jsonl, can.log, summary.json, plot.png; with several\n"
        "  SOURCEs, each in --out/<its name>/, each run against its own simulated gimbal (not on a real bus),\n"
        "  their reports in the order given; the exit status is the worst of theirs\n"
        "exit status: 0 done; 3 done, but the gimbal link was degraded (replies missing, the gimbal\n"
        "  released for silence) or another controller was seen; 4 another controller drives the gimbal\n"
        "  (nothing taken over; --shared-bus to run anyway); 1 the gimbal did not answer at start, or the\n"
        "  bus, source or an output failed mid-run; 2 bad input; 130 Ctrl-C; 143 SIGTERM, 129 SIGHUP,\n"
        "  131 SIGQUIT (the gimbal is told to stop in every case)",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("source", nargs="+", metavar="SOURCE", help="video file, image folder, camera index "
                        "(e.g. 0) or stream URL (udp://, rtsp://, http://); several: see below")
    subject = parser.add_argument_group("subject (default: --detect motion, the largest moving thing)")
    start = subject.add_mutually_exclusive_group()
    start.add_argument("--roi", help="x,y,w,h of the subject in the first frame, in pixels (over an edge: "
                       "--roi=-20,40,64,96)")
    start.add_argument("--detect", choices=("face", "person", "motion"),
                       help="find the subject with a detector (also used to re-acquire it)")
    subject.add_argument("--pick", choices=PICKS,
                         help="which detection to follow (default: largest for motion, else central)")
    subject.add_argument("--tracker", default="default",
                         help=f"tracking backend: {', '.join(available_trackers())} (default: default, which "
                         f"is {DEFAULT_BACKEND} on the model files shipped with gimbaltrack, or on --model-dir's where "
                         f"it holds them all, or {FALLBACK_BACKEND} where they cannot be loaded)")
    subject.add_argument("--model-dir", type=existing_dir,
                         help="folder with optional model files: NanoTrack v3 and VitTrack (instead of the shipped "
                         "ones), NanoTrack v2, FEAR-XS and YuNet (then the face detector)")
    control = parser.add_argument_group("control")
    control.add_argument("--controller", choices=controller_names(), default="pid",
                         help="pid: world-frame Kalman + PID + feed-forward (default); p: proportional baseline")
    control.add_argument("--hfov", type=float, metavar="DEG",
                         help="camera horizontal field of view (default: 24 mm lens on full frame, 73.7)")
    control.add_argument("--rate", type=float, default=25.0, metavar="HZ",
                         help=f"keep-alive rate of the speed command, {MIN_RATE_HZ:g} to {MAX_RATE_HZ:g} "
                         "(default: 25; one command lasts 0.5 s); a new setpoint goes out at once, but "
                         "never more than twice this often")
    control.add_argument("--max-speed", type=float, metavar="DEG_S",
                         help=f"speed limit in deg/s (default: {ControlConfig().max_speed_dps:g}, "
                         f"at most {PROTOCOL_MAX_SPEED_DPS:g})")
    control.add_argument("--attitude-feedback", choices=FEEDBACK_MODES, default="auto",
                         help="use the gimbal attitude (camera on the gimbal); default auto: for live "
                         "sources only")
    control.add_argument("--invert-yaw", action="store_true",
                         help="this gimbal turns the other way for a positive yaw speed (check on hardware)")
    control.add_argument("--invert-pitch", action="store_true",
                         help="this gimbal turns the other way for a positive pitch speed")
    control.add_argument("--invert-yaw-attitude", action="store_true",
                         help="this gimbal reports its yaw with the opposite sign (with --attitude-feedback; "
                         "a gimbal mirrored in both needs both flags)")
    control.add_argument("--invert-pitch-attitude", action="store_true",
                         help="this gimbal reports its pitch with the opposite sign")
    run = parser.add_argument_group("run")
    run.add_argument("--realtime", action="store_true", help="play files at their own frame rate")
    run.add_argument("--fps", type=float, help="frame rate of an image folder (default: 30), or a video file's "
                     f"rate overriding its own; {FPS_RANGE[0]:g} to {FPS_RANGE[1]:g}")
    run.add_argument("--record", action="store_true",
                     help="start camera recording when the subject is acquired, stop it at the end")
    run.add_argument("--max-frames", type=int, help="stop after this many frames")
    run.add_argument("--out", type=out_dir, default=Path("out/track"), help="output folder (default: out/track)")
    run.add_argument("--no-video", action="store_true", help="do not write the annotated video")
    run.add_argument("--video-width", type=int, default=DEFAULT_VIDEO_WIDTH, metavar="PX",
                     help=f"shrink the annotated video to at most this width (default: {DEFAULT_VIDEO_WIDTH}, "
                     "cheap to encode; 0: the source's full size)")
    run.add_argument("--console", metavar="[HOST:]PORT",
                     help="serve the operator console (live view, status, pick the subject, pause, record, "
                     "stop) on this port, on 127.0.0.1 unless a host is given (any other host needs a token; "
                     "the URL is printed on stderr at start)")
    run.add_argument("--console-token", metavar="TOKEN",
                     help="the console's token (default: one is generated when the host is not loopback)")
    run.add_argument("--quiet", action="store_true", help="no progress line, and no line naming the bus "
                     "chosen without -i (the summary names it)")
    run.add_argument("--json", action="store_true", help="print the summary as JSON")
    add_bus_options(parser, fallback="the built-in simulated gimbal")
    link = parser.add_argument_group("gimbal link")
    link.add_argument("--bus-timeout", type=float, default=DEFAULT_TIMEOUT_S, metavar="S",
                      help=f"release the gimbal after this long without a reply, and take it back when it "
                      f"answers (default: {DEFAULT_TIMEOUT_S:g}; above {DEGRADED_SILENCE_S:g}); tracking and "
                      "the outputs go on meanwhile")
    link.add_argument("--shared-bus", action="store_true",
                      help="run even if another host is driving this gimbal (by default track listens "
                      f"{LISTEN_S:g} s first and refuses, exit 4)")
    link.add_argument("--sim-faults", type=parse_sim_faults, metavar="KEY=VALUE,...",
                      help="faults of the built-in simulated gimbal (-i sim), as gimbaltrack sim's options: "
                      "drop, corrupt, fault-direction, delay-ms, nack, silent (START:END s), seed; "
                      "e.g. drop=0.2 or silent=6:6.3")
    add_legacy_order_option(parser)
    add_batch_options(parser, "inputs")
    parser.set_defaults(func=run_track)


def _options(args: argparse.Namespace) -> TrackOptions:
    try:
        roi = parse_roi(args.roi) if args.roi else None
    except ValueError as exc:
        raise CliError(str(exc)) from None
    if not MIN_RATE_HZ <= args.rate <= MAX_RATE_HZ:
        raise CliError(f"--rate takes {MIN_RATE_HZ:g} to {MAX_RATE_HZ:g} Hz (one command lasts 0.5 s), "
                       f"not {args.rate:g}")
    if args.max_speed is not None and not 0 < args.max_speed <= PROTOCOL_MAX_SPEED_DPS:
        raise CliError(f"--max-speed takes 0 < DEG_S <= {PROTOCOL_MAX_SPEED_DPS:g} (the protocol's limit)")
    if args.video_width < 0 or args.video_width == 1:
        raise CliError("--video-width takes 0 (full size) or at least 2 pixels")
    if args.fps is not None and not FPS_RANGE[0] <= args.fps <= FPS_RANGE[1]:
        raise CliError(f"--fps takes {FPS_RANGE[0]:g} to {FPS_RANGE[1]:g} frames a second, not {shown(args.fps)}")
    if args.hfov is not None and not 0 < args.hfov < 180:
        raise CliError(f"--hfov takes 0 < DEG < 180, not {args.hfov:g}")
    if args.max_frames is not None and args.max_frames < 1:
        raise CliError("--max-frames must be at least 1")
    if not DEGRADED_SILENCE_S < args.bus_timeout < float("inf"):
        raise CliError(f"--bus-timeout takes a finite time above {DEGRADED_SILENCE_S:g} s (a shorter silence "
                       f"only degrades the link), not {args.bus_timeout:g}")
    detect = args.detect or (None if roi else DEFAULT_DETECTOR)
    return TrackOptions(
        out_dir=args.out, roi=roi, detect=detect,
        pick=args.pick or ("largest" if detect == "motion" else "central"),
        tracker=args.tracker, model_dir=args.model_dir, controller=args.controller,
        hfov_deg=args.hfov, rate_hz=args.rate, max_speed_dps=args.max_speed, record=args.record,
        realtime=args.realtime, attitude_feedback=args.attitude_feedback,
        yaw_sign=-1 if args.invert_yaw else 1, pitch_sign=-1 if args.invert_pitch else 1,
        yaw_attitude_sign=-1 if args.invert_yaw_attitude else 1,
        pitch_attitude_sign=-1 if args.invert_pitch_attitude else 1,
        max_frames=args.max_frames, video=not args.no_video, video_width=args.video_width or None,
        bus_timeout=args.bus_timeout,
        progress=not args.quiet)


def run_track(args: argparse.Namespace) -> int:
    # main() turns SIGTERM, SIGHUP and SIGQUIT into SignalExit: every ``with`` below stops the
    # gimbal on the way out, and _run finalises the outputs first
    options = _options(args)  # checked once for all the inputs
    batch_jobs(args)  # --jobs and --scheduler too, though one input runs here
    if len(args.source) > 1:
        return run_track_batch(args, run_track)
    [args.source] = args.source
    return _open_and_run(options, args)


def _open_and_run(options: TrackOptions, args: argparse.Namespace) -> int:
    try:
        source = open_source(args.source, realtime=args.realtime, fps=args.fps,
                             waiting=None if args.quiet else _say_waiting)
    except SourceError as exc:
        raise CliError(str(exc)) from None
    with source:
        ignored = [name for name, given in (("--realtime", args.realtime), ("--fps", args.fps is not None))
                   if given and source.is_live]
        if ignored:
            print(f"gimbaltrack track: note: ignoring {' and '.join(ignored)} for a live source (it runs at "
                  "its own rate)", file=sys.stderr)
        try:
            if options.roi is not None:
                check_roi_in_frame(options.roi, source.size)
            subject = make_subject(options)  # missing model files fail before --out is created
        except (ValueError, OSError) as exc:
            raise CliError(str(exc)) from None
        where, chosen = choose_track_bus(args)
        if args.sim_faults is not None and args.interface != SIM_INTERFACE:
            raise CliError("--sim-faults is for the built-in simulated gimbal (-i sim)")
        with _console_socket(args) as console, open_host_bus(args) as bus, ExitStack() as held:
            # from the output folder's creation until a session exists that can finish its outputs,
            # a Ctrl-C or SIGTERM is held; _session delivers it where the session writes its summary
            pending_signals = held.enter_context(deferred_signals())
            make_out_dir(options.out_dir)
            can_log = _can_log(options.out_dir / "can.log")
            try:
                with GimbalClient(bus, tx_id=args.tx_id, rx_id=args.rx_id, listeners=[can_log],
                                  legacy_attitude_order=args.legacy_order) as client:
                    if not (args.shared_bus or args.interface == SIM_INTERFACE):
                        _refuse_a_second_controller(client, where)
                    try:
                        session = _session(options, source, client, where, subject, can_log, held)
                    except CliError:  # it says why the run ended; a signal held meanwhile adds nothing
                        pending_signals.clear()
                        raise
                    if chosen and not args.quiet:  # once the gimbal answered: an error before names the bus
                        print(chosen, file=sys.stderr, flush=True)
                    if console is None:
                        return _run(session, args)
                    from pipelines.console.track import serving
                    with serving(session, *console, args.console_token):
                        return _run(session, args)
            finally:
                can_log.stop()


def _refuse_a_second_controller(client: GimbalClient, where: str) -> None:
    """Listen ``LISTEN_S`` before taking control: another host's speed or control commands on our
    transmit id mean someone drives this gimbal already, and two controllers fight over it."""
    if client.other_hosts.wait_for_control(LISTEN_S):
        time.sleep(min(LISTEN_S, 0.1))  # a few more of its commands, to name what it sends
        raise CliError(f"another host is driving the gimbal on {where}: it sent "
                       f"{client.other_hosts.seen().describe()} on 0x{client.transport.tx_id:03X}; "
                       "stop it first, or pass --shared-bus to run anyway", exit_code=EXIT_OTHER_CONTROLLER)


@contextmanager
def _console_socket(args: argparse.Namespace) -> Iterator[tuple[Any, socket.socket] | None]:
    """The console's address and its listening socket, bound before anything is created (a port
    in use is bad input); None without ``--console``."""
    if args.console is None:
        if args.console_token is not None:
            raise CliError("--console-token needs --console")
        yield None
        return
    try:
        from pipelines.console.address import bind, parse_console_address
    except ImportError as exc:
        raise CliError(f"--console needs aiohttp ({exc}): pip install 'gimbaltrack[console]'") from None
    try:
        address = parse_console_address(args.console)
    except ValueError as exc:
        raise CliError(str(exc)) from None
    if args.console_token is not None and len(args.console_token) < 8:
        raise CliError("--console-token must be at least 8 characters")
    try:
        sock = bind(address)
    except OSError as exc:
        raise CliError(f"cannot serve the console on {address.host}:{address.port}: "
                       f"{exc.strerror or exc}") from None
    with sock:
        yield address, sock


def _say_waiting(description: str) -> None:
    print(f"gimbaltrack track: waiting for {description}: nothing received yet (Ctrl-C stops)",
          file=sys.stderr, flush=True)


def _can_log(path: Path) -> CanLogWriter:
    try:
        return CanLogWriter(path)
    except OSError as exc:
        raise CliError(f"cannot write in output folder {path.parent}: {exc.strerror}") from None


def _session(options: TrackOptions, source: FrameSource, client: GimbalClient, where: str,
             subject: tuple[Detector | None, SubjectTracker], can_log: CanLogWriter,
             held_signals: ExitStack) -> TrackSession:
    try:
        session = TrackSession(options, source, client, where, subject, can_log)
    except (ValueError, FileNotFoundError, OSError) as exc:
        raise CliError(str(exc)) from None
    try:
        held_signals.close()  # a signal held while the outputs were opened arrives here
        session.start()
    except KeyboardInterrupt:
        session.finish("interrupted while starting (SIGINT)")
        raise
    except SignalExit as exc:
        session.finish(f"terminated while starting ({exc.signal_name})")
        raise
    except GimbalTimeoutError as exc:
        session.finish("gimbal not answering", str(exc))
        raise CliError(f"the gimbal does not answer on {where} ({exc}); check the "
                       "wiring, bitrate (1 Mbit/s) and ids", exit_code=1) from None
    except GimbalError as exc:  # a NACK or an undecodable answer to the start-up commands
        session.finish("gimbal refused to start", str(exc))
        raise CliError(f"the gimbal on {where} refused to start ({exc})", exit_code=1) from None
    return session


def _run(session: TrackSession, args: argparse.Namespace) -> int:
    try:
        session.run()
    except KeyboardInterrupt:
        _report(session.finish("interrupted (SIGINT)"), args)
        return EXIT_INTERRUPTED
    except SignalExit as exc:
        _report(session.finish(f"terminated ({exc.signal_name})"), args)
        return int(exc.code or 1)
    except SourceError as exc:
        session.finish("source failed", str(exc))
        raise CliError(f"{exc} (outputs so far are in {session.options.out_dir})", exit_code=1) from None
    except (GimbalError, OSError) as exc:
        session.finish("gimbal or bus failed" if isinstance(exc, GimbalError) else "output failed", str(exc))
        raise _stopped_with(exc, session) from None
    except Exception as exc:  # a bug: keep the outputs and stop the gimbal, then let it show
        session.finish("failed", repr(exc))
        raise
    summary = session.finish()
    if summary["status"] == "output failed":  # an output that could not be finalised (a full disk)
        raise _stopped_with(summary["error"], session)
    _report(summary, args)
    return EXIT_DEGRADED_LINK if link_degraded(summary["bus_health"]) else 0


def _stopped_with(error: object, session: TrackSession) -> CliError:
    return CliError(f"{error} (the gimbal was told to stop; outputs so far are in {session.options.out_dir})",
                    exit_code=1)


#: A file that ends before this share of the frames its header announces was probably cut short.
EARLY_END_FRACTION = 0.95


def _report(summary: dict[str, Any], args: argparse.Namespace) -> None:
    expected = summary["frames_expected"]
    if summary["status"] == "end of source" and expected and summary["frames"] < EARLY_END_FRACTION * expected:
        print(f"gimbaltrack track: warning: the source ended after {summary['frames']} of the {expected} "
              "frames its header announces (a truncated or damaged file?)", file=sys.stderr)
    if args.json:
        print(json.dumps(summary, indent=2))
        return
    latency = summary["latency_ms"]
    states = ", ".join(f"{k} {v}" for k, v in sorted(summary["states"].items()))
    lines = [f"{summary['status']}: {summary['frames']} frames in {summary['elapsed_s']:.1f} s "
             f"({summary['fps'] or 0:.1f} fps) from {summary['source']}",
             f"subject: {states or 'never seen'}; tracker {summary['tracker']}, "
             f"controller {summary['controller']}, bus {summary['bus']}"]
    if summary["first_acquired_s"] is None:
        lines.append("subject never acquired: no detection was confirmed (try --roi x,y,w,h, "
                     "or another --detect)")
    if latency["count"]:
        lines.append(f"capture -> command latency: p50 {latency['p50']:.1f} ms, "
                     f"p95 {latency['p95']:.1f} ms, p99 {latency['p99']:.1f} ms")
    if summary["recording"]["requested"]:
        lines.append(f"recording: {_recording_text(summary['recording'])}")
    lines.append(link_report(summary["bus_health"], summary["speed_commands"].get("sent", 0)))
    lines.append(f"outputs: {Path(summary['outputs']['summary']).parent}")
    print("\n".join(lines), file=sys.stdout)


def _recording_text(recording: dict[str, Any]) -> str:
    if not recording.get("started"):
        return f"not started ({recording.get('error', 'the subject was never acquired')})"
    if recording.get("error"):
        return f"failed: {recording['error']}"
    started = "started (confirmed)" if recording.get("start_confirmed") else "started (NOT confirmed)"
    stopped = "stopped (confirmed)" if recording.get("stop_confirmed") else "stop NOT confirmed"
    return f"{started}, {stopped}"
