"""The ``gimbaltrack`` command's parser and run: one module per subcommand. ``pipelines.cli.main``
(the console script) imports this module with the signals held."""
from __future__ import annotations

import argparse
import importlib
import logging
import os
import signal
import sys
from collections.abc import Iterable

from gimbal.signals import SignalExit, blocked_signals, exit_on_signals
from pipelines.cli.common import EXIT_INTERRUPTED, CliError

# Each module defines ``register(subparsers)``, which adds its parser and sets ``func(args) -> int``.
SUBCOMMAND_MODULES = [
    "pipelines.cli.eval_cmd",
    "pipelines.cli.track_cmd",
    "pipelines.cli.decode_cmd",
    "pipelines.cli.replay_cmd",
    "pipelines.cli.sim_cmd",
    "pipelines.cli.gimbal_cmd",
    "pipelines.cli.simulate_cmd",
]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="gimbaltrack",
        description="Keep a subject framed with a DJI RS gimbal: track it in video, "
        "turn its position into yaw/pitch rates, and drive the gimbal over CAN (DJI R SDK).",
    )
    _add_logging_options(parser, False)
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in SUBCOMMAND_MODULES:
        importlib.import_module(name).register(subparsers)
    pending = list(subparsers.choices.values())
    while pending:  # after the command too, at any depth: gimbaltrack gimbal angles --debug
        subparser = pending.pop()
        _add_logging_options(subparser, argparse.SUPPRESS)
        pending += [p for action in subparser._actions if isinstance(action, argparse._SubParsersAction)
                    for p in action.choices.values()]
    return parser


def _add_logging_options(parser: argparse.ArgumentParser, default: object) -> None:
    parser.add_argument("-v", "--verbose", action="store_true", default=default,
                        help="log warnings too (retries, timeouts, best-effort stops)")
    parser.add_argument("--debug", action="store_true", default=default, help="log debug output and show tracebacks")


def quiet_opencv(argv: list[str]) -> None:
    """Keep OpenCV's and FFmpeg's own warnings (``[ WARN:0@1.7] ...``, ``moov atom not found``) off
    the terminal, where they bury the one-line error that explains them, unless ``--debug`` is
    given or the variables are set already. Effective only before cv2 is imported."""
    if "--debug" not in argv:
        os.environ.setdefault("OPENCV_LOG_LEVEL", "ERROR")
        os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "8")  # AV_LOG_FATAL


def main(argv: list[str] | None = None, release: Iterable[int] | None = None) -> int:
    """Parse ``argv`` and run the subcommand; its exit status. ``release``: the signal mask to go
    back to once the handlers are in place, when the caller holds the signals already."""
    prog, debug = "gimbaltrack", False
    quiet_opencv(sys.argv[1:] if argv is None else argv)
    try:
        with exit_on_signals():  # from the start: a SIGTERM while loading must not be a traceback
            try:
                with blocked_signals():  # nor lost, or an import error, while numpy, SciPy and cv2 load
                    parser = build_parser()
            finally:
                if release is not None:  # what arrived while the console script held them comes now
                    signal.pthread_sigmask(signal.SIG_SETMASK, release)
            args = parser.parse_args(argv)
            prog, debug = f"gimbaltrack {args.command}", args.debug
            level = logging.DEBUG if args.debug else logging.WARNING if args.verbose else logging.ERROR
            logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
            try:
                status = int(args.func(args) or 0)
                try:
                    sys.stdout.flush()  # a failure to write the results shows here, not at exit
                except BrokenPipeError:  # the reader left: the run's own status still stands (130, ...)
                    _drop_stdout()
                return status
            except CliError as exc:
                if args.debug:
                    raise
                print(f"{prog}: error: {exc}", file=sys.stderr)
                return exc.exit_code
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except SignalExit as exc:
        print(f"{prog}: terminated ({exc.signal_name})", file=sys.stderr)
        return int(exc.code)
    except BrokenPipeError:  # the reader went away (e.g. `| head`): not an error of ours
        _drop_stdout()
        return 0
    except OSError as exc:  # one no subcommand words itself, e.g. stdout on a full disk (> /dev/full)
        if debug:
            raise
        print(f"{prog}: error: {str(exc) or type(exc).__name__}", file=sys.stderr)  # TimeoutError() says nothing
        try:
            sys.stdout.flush()
        except OSError:
            _drop_stdout()
        return 1


def _drop_stdout() -> None:
    """Point stdout at /dev/null, so that Python's own flush at exit cannot fail a second time."""
    os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
