"""The ``gimbaltrack`` command's parser and run: one module per subcommand. ``pipelines.cli.main``
(the console script) imports this module with the signals held."""
from __future__ import annotations

import argparse
import importlib
import logging
import sys
import warnings
from collections.abc import Iterable
from dataclasses import dataclass

from gimbal.signals import SignalExit, blocked_signals, exit_on_signals
from pipelines.cli.common import EXIT_INTERRUPTED, CliError
from pipelines.cli.process import drop_stdout, quiet_opencv, release_signals, standard_streams
from pipelines.cli.profile import Profile, add_profile_option, apply_profile, blame, profile_path, read_profile

# Each module defines ``register(subparsers)``, which adds its parser and sets ``func(args) -> int``;
# module ``pipelines.cli.NAME_cmd`` is the command NAME.
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
#: Each command's line in ``gimbaltrack --help``, as its module registers it (a test checks they
#: agree): the list is shown without importing the modules, which load OpenCV and SciPy.
COMMAND_HELP = {
    "eval": "score a tracker on sequences with ground truth (precision@20px, success AUC, fps)",
    "track": "track a subject in video and keep it framed with the gimbal",
    "decode": "decode DJI R SDK packets from hex or a CAN log into JSON lines",
    "replay": "play a recorded CAN log back: decoded packets, a summary, optionally onto a bus",
    "sim": "run the simulated DJI RS gimbal on a CAN bus",
    "gimbal": "talk to a DJI RS gimbal: read, move, set, camera",
    "simulate": "run tracker + control + client against the simulated gimbal on a sequence",
    "config": "print the effective settings (rig profile, python-can configuration, defaults)",
    "doctor": "check a gimbal rig: bus, ids, replies, latency, pushes, another controller",
}


def command_name(module: str) -> str:
    return module.rsplit(".", 1)[-1].removesuffix("_cmd")


class LazySubcommands(argparse._SubParsersAction):
    """Subcommands whose modules are imported when the command is chosen (``load``), so that
    ``gimbaltrack gimbal ...`` never loads the tracker's OpenCV and SciPy, and ``gimbaltrack --help``
    lists the commands from ``COMMAND_HELP`` alone."""

    def __init__(self, *args: object, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)
        self.unloaded: dict[str, str] = {}  # command -> its module, not imported yet

    def add_lazy(self, module: str) -> None:
        name = command_name(module)
        self.add_parser(name, help=COMMAND_HELP[name], add_help=False)  # a stand-in with the help line
        self.unloaded[name] = module

    def load(self, name: str) -> argparse.ArgumentParser:
        """The command's real parser, its module imported and registered on first use."""
        module = self.unloaded.pop(name, None)
        if module is not None:
            del self._name_parser_map[name]
            lines = len(self._choices_actions)
            importlib.import_module(module).register(self)
            del self._choices_actions[lines:]  # the stand-in's line stays, in its place
            _add_common_options(self._name_parser_map[name])
        return self._name_parser_map[name]

    def load_all(self) -> None:
        for name in list(self.unloaded):
            self.load(name)

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace,
                 values: list[str], option_string: str | None = None) -> None:
        self.load(values[0])
        super().__call__(parser, namespace, values, option_string)


def build_parser(lazy: bool = False) -> argparse.ArgumentParser:
    """The ``gimbaltrack`` parser; ``lazy``: each command's module is imported only when the
    command is parsed (``subcommands(parser).load_all()`` imports them all)."""
    parser = argparse.ArgumentParser(
        prog="gimbaltrack",
        description="Keep a subject framed with a DJI RS gimbal: track it in video, "
        "turn its position into yaw/pitch rates, and drive the gimbal over CAN (DJI R SDK).",
    )
    _add_logging_options(parser, False)
    add_profile_option(parser)
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True, action=LazySubcommands)
    for module in SUBCOMMAND_MODULES:
        subparsers.add_lazy(module)
    if not lazy:
        subparsers.load_all()
    return parser


def subcommands(parser: argparse.ArgumentParser) -> LazySubcommands:
    return next(a for a in parser._actions if isinstance(a, LazySubcommands))


def _add_common_options(subparser: argparse.ArgumentParser) -> None:
    """The logging and profile options on a command and, at any depth, its own subcommands (given
    after the command too: gimbaltrack gimbal angles --debug)."""
    pending = [subparser]
    while pending:
        current = pending.pop()
        _add_logging_options(current, argparse.SUPPRESS)
        add_profile_option(current, argparse.SUPPRESS)
        pending += [p for action in current._actions if isinstance(action, argparse._SubParsersAction)
                    for p in action.choices.values()]


def _add_logging_options(parser: argparse.ArgumentParser, default: object) -> None:
    parser.add_argument("-v", "--verbose", action="store_true", default=default,
                        help="log warnings too (retries, timeouts, best-effort stops)")
    parser.add_argument("--debug", action="store_true", default=default, help="log debug output and show tracebacks")


def _one_line_warning(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                      line: str | None = None) -> str:
    """A warning (e.g. the default tracker's model could not be loaded) as one line, like the errors."""
    return f"gimbaltrack: warning: {message}\n"


def main(argv: list[str] | None = None, release: Iterable[int] | None = None) -> int:
    """Parse ``argv`` and run the subcommand; its exit status. ``release``: the signal mask to go
    back to once the handlers are in place, when the caller holds the signals already."""
    given = sys.argv[1:] if argv is None else argv
    run = _Run(debug="--debug" in given)  # until parsed: an OSError may come first
    standard_streams()
    quiet_opencv(given)
    warnings.formatwarning = _one_line_warning
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
                with blocked_signals():  # nor lost, or an import error, while the modules load
                    parser = build_parser(lazy=True)
            finally:  # what arrived while the console script held them comes now
                release_signals(release)
            given = sys.argv[1:] if argv is None else argv
            profile = _profile(given, parser, run)
            with blocked_signals():  # the chosen command's module loads while parsing
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
        drop_stdout()
        return 0
    except OSError as exc:  # one no subcommand words itself, e.g. stdout on a full disk (> /dev/full)
        return _unwritten(run.prog, exc, run.debug)


def _profile(argv: list[str], parser: argparse.ArgumentParser, run: _Run) -> Profile | None:
    """The rig profile the run uses, applied to the parser's defaults; a bad one ends the run with
    its one-line error and status 2, as a bad option would."""
    path = profile_path(argv)
    if path is None:
        return None
    with blocked_signals():  # a profile may name any command's options: all are loaded
        subcommands(parser).load_all()
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
        drop_stdout()
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
        drop_stdout()
    return 1
