"""The ``gimbaltrack`` command's parser and run: one module per subcommand. ``pipelines.cli.main``
(the console script) imports this module with the signals held."""
from __future__ import annotations

import argparse
import errno
import importlib
import io
import logging
import os
import signal
import sys
from collections.abc import Iterable
from dataclasses import dataclass

from gimbal.signals import SignalExit, blocked_signals, exit_on_signals
from pipelines.cli.common import EXIT_INTERRUPTED, CliError, hold_on_devnull
from pipelines.cli.profile import Profile, add_profile_option, apply_profile, blame, profile_path, read_profile

# Each module defines ``register(subparsers)``, which adds its parser and sets ``func(args) -> int``.
SUBCOMMAND_MODULES = [
    "pipelines.cli.eval_cmd",
    "pipelines.cli.track_cmd",
    "pipelines.cli.decode_cmd",
    "pipelines.cli.replay_cmd",
    "pipelines.cli.sim_cmd",
    "pipelines.cli.gimbal_cmd",
    "pipelines.cli.simulate_cmd",
    "pipelines.cli.config_cmd",
    "pipelines.cli.doctor_cmd",
]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="gimbaltrack",
        description="Keep a subject framed with a DJI RS gimbal: track it in video, "
        "turn its position into yaw/pitch rates, and drive the gimbal over CAN (DJI R SDK).",
    )
    _add_logging_options(parser, False)
    add_profile_option(parser)
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in SUBCOMMAND_MODULES:
        importlib.import_module(name).register(subparsers)
    pending = list(subparsers.choices.values())
    while pending:  # after the command too, at any depth: gimbaltrack gimbal angles --debug
        subparser = pending.pop()
        _add_logging_options(subparser, argparse.SUPPRESS)
        add_profile_option(subparser, argparse.SUPPRESS)
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
    given = sys.argv[1:] if argv is None else argv
    run = _Run(debug="--debug" in given)  # until parsed: an OSError may come first
    if sys.stderr is None:  # fd 2 closed (2>&-): print(file=None) wrote the errors among the results
        sys.stderr = closed_stderr()
    quiet_opencv(given)
    if sys.stdout is None:  # fd 1 closed (>&-): Python gives no stdout, and print() drops the results
        sys.stdout = ClosedStdout()
    try:
        status = _run(argv, release, run)
    except SystemExit:  # argparse's --help (0) or usage error (2): its text is flushed here, not at exit
        if failed := _flushed(run, 0):
            return failed
        raise
    return _flushed(run, status)  # after a signal too: what the run printed before it


@dataclass
class _Run:
    """What the one-line errors of a run name (the command, whether ``--debug`` was given), and
    whether its results were flushed already (once is enough: a failure is said once)."""

    prog: str = "gimbaltrack"
    debug: bool = False
    flushed: bool = False


def _run(argv: list[str] | None, release: Iterable[int] | None, run: _Run) -> int:
    """``main`` but for argparse's exits: the subcommand's status, or the status of how it ended."""
    try:
        with exit_on_signals():  # from the start: a SIGTERM while loading must not be a traceback
            try:
                with blocked_signals():  # nor lost, or an import error, while numpy, SciPy and cv2 load
                    parser = build_parser()
            finally:
                if release is not None:  # what arrived while the console script held them comes now
                    signal.pthread_sigmask(signal.SIG_SETMASK, release)
            given = sys.argv[1:] if argv is None else argv
            profile = _profile(given, parser, run)
            args = parser.parse_args(argv)
            run.prog, run.debug = f"gimbaltrack {args.command}", args.debug
            level = logging.DEBUG if args.debug else logging.WARNING if args.verbose else logging.ERROR
            logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
            try:
                status = int(args.func(args) or 0)
            except CliError as exc:
                if args.debug:
                    raise
                message = str(exc) if profile is None else blame(str(exc), profile, given, parser)
                print(f"{run.prog}: error: {message}", file=sys.stderr)
                status = exc.exit_code
            return _flushed(run, status)  # here too: a Ctrl-C while a slow reader holds it is handled
    except KeyboardInterrupt:
        print(f"{run.prog}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except SignalExit as exc:
        print(f"{run.prog}: terminated ({exc.signal_name})", file=sys.stderr)
        return int(exc.code)
    except BrokenPipeError:  # the reader went away (e.g. `| head`): not an error of ours
        _drop_stdout()
        return 0
    except OSError as exc:  # one no subcommand words itself, e.g. stdout on a full disk (> /dev/full)
        return _unwritten(run.prog, exc, run.debug)


def _profile(argv: list[str], parser: argparse.ArgumentParser, run: _Run) -> Profile | None:
    """The rig profile the run uses, applied to the parser's defaults; a bad one ends the run with
    its one-line error and status 2, as a bad option would."""
    path = profile_path(argv)
    if path is None:
        return None
    try:
        profile = read_profile(path, parser)
    except CliError as exc:
        if run.debug:
            raise
        print(f"{run.prog}: error: {exc}", file=sys.stderr)
        raise SystemExit(2) from None
    apply_profile(parser, profile)
    return profile


def _flushed(run: _Run, status: int) -> int:
    """``status`` once the results are flushed (a failure to write them shows here, not at exit):
    a reader that left changes nothing; a full disk or a closed stdout is a line, and exit 1
    unless the run ended with its own status already (130, 2, ...)."""
    if run.flushed:
        return status
    run.flushed = True
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        _drop_stdout()
    except OSError as exc:
        failed = _unwritten(run.prog, exc, run.debug)  # said whatever the status
        return status or failed
    return status


def _unwritten(prog: str, exc: OSError, debug: bool) -> int:
    """Exit status 1 after a one-line error for ``exc`` (re-raised with ``--debug``); stdout,
    which may be what failed, is emptied so that the flush at exit cannot fail again."""
    if debug:
        raise exc
    print(f"{prog}: error: {str(exc) or type(exc).__name__}", file=sys.stderr)  # TimeoutError() says nothing
    try:
        sys.stdout.flush()
    except OSError:
        _drop_stdout()
    return 1


STDOUT_FD, STDERR_FD = 1, 2


def closed_stderr() -> io.TextIOBase:
    """``sys.stderr`` when fd 2 was closed (``2>&-``), where Python gives None and ``print(...,
    file=sys.stderr)`` writes to stdout: the user chose not to see the errors, so they go to
    /dev/null, never among the results; the exit status still tells a failure."""
    hold_on_devnull(STDERR_FD)
    return open(STDERR_FD, "w", closefd=False)


class ClosedStdout(io.TextIOBase):
    """``sys.stdout`` when fd 1 was closed (``>&-``). It holds fd 1 open on /dev/null, so that no
    output file opened later takes that number, and flushing what was written raises EBADF: a
    closed stdout is reported like a full disk's (one line, exit 1), and a run's files are kept."""

    def __init__(self) -> None:
        super().__init__()
        hold_on_devnull(STDOUT_FD)
        self._written = False

    def writable(self) -> bool:
        return True

    def fileno(self) -> int:
        return STDOUT_FD

    def write(self, text: str) -> int:
        self._written = self._written or bool(text)
        return len(text)

    def flush(self) -> None:
        if self._written:  # said once: the flush at exit finds nothing more
            self._written = False
            raise OSError(errno.EBADF, "stdout is closed: the results went nowhere")


def _drop_stdout() -> None:
    """Point stdout at /dev/null, so that Python's own flush at exit cannot fail a second time."""
    hold_on_devnull(sys.stdout.fileno())
