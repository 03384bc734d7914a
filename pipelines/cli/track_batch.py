"""``gimbaltrack track SOURCE SOURCE ...``: each input a run of its own, against its own simulated
gimbal, into its own folder ``OUT/<input name>/``; side by side with ``--jobs`` or ``--scheduler``.
A real bus is refused: one gimbal cannot follow two subjects."""
from __future__ import annotations

import argparse
import io
import json
import re
import sys
from collections.abc import Callable
from contextlib import redirect_stderr, redirect_stdout
from dataclasses import dataclass
from pathlib import Path

from gimbal.signals import SignalExit
from pipelines.batch import BatchError, Outcome, run_batch
from pipelines.cli.batch_options import batch_jobs
from pipelines.cli.bus import SIM_INTERFACE, choose_track_bus
from pipelines.cli.common import EXIT_INTERRUPTED, CliError
from pipelines.outputs.progress import ProgressReporter

PROG = "gimbaltrack track"


@dataclass(frozen=True)
class TrackJob:
    """One input's run: ``run`` (the single-input ``gimbaltrack track``) with the command's options
    for this input alone; ``capture``: keep what it prints to hand back (in a worker), else print it
    as it comes."""

    run: Callable[[argparse.Namespace], int]
    args: argparse.Namespace
    capture: bool


@dataclass(frozen=True)
class TrackResult:
    """How one input's run ended: its exit status, what it printed, and its one-line error."""

    status: int
    stdout: str = ""
    stderr: str = ""
    error: str | None = None


def run_track_batch(args: argparse.Namespace, run: Callable[[argparse.Namespace], int]) -> int:
    """Run every ``args.source`` with ``run``, which takes one (a module-level function: workers load
    it by name); the exit status of the worst run (0 when all went well)."""
    jobs = batch_jobs(args)
    choose_track_bus(args)  # no -i: python-can's configuration, or the simulated gimbal
    if args.interface != SIM_INTERFACE:
        raise CliError(f"{len(args.source)} inputs need the simulated gimbal, each its own (one gimbal cannot "
                       "follow two subjects): give one SOURCE with -i/--interface")
    folders = output_folders(args.source, args.out)
    here = args.scheduler is None and min(jobs, len(args.source)) == 1
    inputs = [(source, TrackJob(run, _one_input(args, source, folder, quiet=args.quiet or not here), not here))
              for source, folder in zip(args.source, folders)]
    statuses: list[int] = []

    def show(outcome: Outcome) -> None:
        result: TrackResult = outcome.result or TrackResult(1, error=outcome.error)
        sys.stdout.write(result.stdout)
        sys.stdout.flush()
        sys.stderr.write(result.stderr)
        if outcome.detail and args.debug:
            sys.stderr.write(outcome.detail)
        if result.error is not None:
            print(f"{PROG}: error: {result.error}", file=sys.stderr, flush=True)
        statuses.append(result.status)

    if here:
        run_batch(track_one, inputs, show=show)
    else:
        reporter = ProgressReporter(None, enabled=not args.quiet)
        try:
            run_batch(track_one, inputs, jobs=jobs, scheduler=args.scheduler, show=show,
                      finished=_progress(reporter, folders))
        except BatchError as exc:
            raise CliError(str(exc)) from None
        finally:
            reporter.close()
    return max(statuses, default=0)


def output_folders(sources: list[str], out: Path) -> list[Path]:
    """``OUT/<name>`` for each source (a file's stem, a folder's name, else the text made safe);
    a one-line error when two would share one."""
    folders: dict[Path, str] = {}
    for source in sources:
        path = Path(source)
        name = path.stem if path.is_file() else path.name if path.is_dir() else source
        folder = out / (re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._") or "input")
        if folder in folders:
            raise CliError(f"inputs {folders[folder]} and {source} would both write to {folder}: rename one, "
                           "or run them apart")
        folders[folder] = source
    return list(folders)


def _one_input(args: argparse.Namespace, source: str, folder: Path, quiet: bool) -> argparse.Namespace:
    one = argparse.Namespace(**vars(args))
    one.source, one.out, one.quiet = [source], folder, quiet
    return one


def track_one(job: TrackJob) -> TrackResult:
    """One input's ``gimbaltrack track`` run. Here (not captured) a stop ends the batch too: the
    run has finished its outputs and reported, and the stop goes on unwinding."""
    source = job.args.source[0]
    if not job.capture:
        try:
            status = job.run(job.args)
        except CliError as exc:
            return TrackResult(exc.exit_code, error=f"{source}: {exc}")
        if status == EXIT_INTERRUPTED:
            raise KeyboardInterrupt
        if status > 128:
            raise SignalExit(status)
        return TrackResult(status)
    stdout, stderr = io.StringIO(), io.StringIO()
    with redirect_stdout(stdout), redirect_stderr(stderr):
        try:
            status, error = job.run(job.args), None
        except CliError as exc:
            status, error = exc.exit_code, f"{source}: {exc}"
    return TrackResult(status, stdout.getvalue(), stderr.getvalue(), error)


def _progress(reporter: ProgressReporter, folders: list[Path]) -> Callable[[Outcome], None]:
    """A batch progress line: frames done (from each finished run's summary.json) and inputs done."""
    done: list[int] = []

    def finished(outcome: Outcome) -> None:
        done.append(_frames(folders[outcome.index] / "summary.json"))
        reporter.update(sum(done), f"{len(done)}/{len(folders)} inputs", force=True)
    return finished


def _frames(summary: Path) -> int:
    """The frames a finished run counted; 0 when its summary cannot be read here (a run that failed
    early, or one on a Dask worker with a disk of its own)."""
    try:
        return int(json.loads(summary.read_text())["frames"])
    except (OSError, ValueError, KeyError, TypeError):
        return 0
