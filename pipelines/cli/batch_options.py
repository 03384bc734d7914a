"""``--jobs`` and ``--scheduler``: the options of the commands that run several inputs at once."""
from __future__ import annotations

import argparse
import os

from pipelines.cli.common import CliError


def add_batch_options(parser: argparse.ArgumentParser, inputs: str) -> None:
    """The two ways to run several ``inputs`` (a plural noun for the help) side by side."""
    group = parser.add_argument_group("several inputs at once")
    group.add_argument("--jobs", type=_integer, metavar="N",
                       help=f"run up to N {inputs} at once in worker processes on this machine, one thread "
                       f"each (default: 1, one after the other; more than the {inputs} given is cut to "
                       f"their number; this machine has {os.cpu_count()} cores). Results and their order "
                       "are those of a run with --jobs 1")
    group.add_argument("--scheduler", metavar="ADDRESS",
                       help="run them on the Dask cluster whose scheduler is at ADDRESS (e.g. "
                       "tcp://scheduler-host:8786; needs pip install 'gimbaltrack[dask]', and every worker needs "
                       "gimbaltrack and the input paths); not with --jobs")


def batch_jobs(args: argparse.Namespace) -> int:
    """The ``--jobs`` asked for (1 when not given); a one-line error for 0 or less, or beside
    ``--scheduler``."""
    if args.jobs is not None and args.scheduler is not None:
        raise CliError("--jobs runs on this machine, --scheduler on a Dask cluster: give one of them")
    if args.jobs is not None and args.jobs < 1:
        raise CliError(f"--jobs takes 1 or more worker processes, not {args.jobs}")
    if args.scheduler is not None and not args.scheduler.strip():
        raise CliError("--scheduler takes the address of a Dask scheduler, e.g. tcp://scheduler-host:8786")
    return args.jobs or 1


def _integer(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
