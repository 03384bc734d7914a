"""Wall time of ``gimbaltrack eval`` over every shared sequence, one after the other (``--jobs 1``)
and in worker processes (``--jobs N``), alternated in one run so that both see the same load.

Checks that every run prints the same rows (timings aside), then prints each run's wall time and
CPU time (its processes', all cores), the machine's load average beside it (other sessions share
the 2 cores, and a saturated machine has no core to spare for a second worker), the medians and
their ratio. Usage:

    .venv/bin/python benchmarks/bench_eval_jobs.py [--jobs N] [--repeats R] [SEQ ...]
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

from machine import describe_machine
from tracker.evaluation.data_paths import shared_sequences

ROOT = Path(__file__).resolve().parents[1]


def timed_eval(sequences: list[str], jobs: int) -> tuple[float, float, list[dict]]:
    """Wall and CPU seconds of one ``gimbaltrack eval --json --jobs`` call (its workers included),
    and its rows without the fps fields."""
    command = [sys.executable, "-m", "pipelines.cli", "eval", *sequences, "--json", "--jobs", str(jobs)]
    cpu_before = _children_cpu()
    start = time.perf_counter()
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, check=True)
    seconds = time.perf_counter() - start
    rows = [{k: v for k, v in json.loads(line).items() if "fps" not in k} for line in done.stdout.splitlines()]
    return seconds, _children_cpu() - cpu_before, rows


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)  # waited-for descendants: the workers too
    return usage.ru_utime + usage.ru_stime


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sequences", nargs="*", help="sequence folders (default: every shared sequence)")
    parser.add_argument("--jobs", type=int, default=2, help="worker processes of the parallel runs (default 2)")
    parser.add_argument("--repeats", type=int, default=2, help="runs of each kind, alternated (default 2)")
    args = parser.parse_args(argv)
    sequences = args.sequences or [str(p) for p in shared_sequences()]
    if not sequences:
        parser.error("no sequences given and no shared data found")
    print(describe_machine())
    print(f"{len(sequences)} sequences, --jobs 1 against --jobs {args.jobs}, {args.repeats} runs each, alternated")
    times: dict[int, list[float]] = {1: [], args.jobs: []}
    reference: list[dict] | None = None
    for _ in range(args.repeats):
        for jobs in (1, args.jobs):
            seconds, cpu, rows = timed_eval(sequences, jobs)
            reference = reference or rows
            if rows != reference:
                print(f"--jobs {jobs}: rows differ from the first run's", file=sys.stderr)
                return 1
            times[jobs].append(seconds)
            print(f"--jobs {jobs}: {seconds:6.1f} s wall, {cpu:6.1f} s CPU, load average {os.getloadavg()[0]:.1f}")
    serial, parallel = statistics.median(times[1]), statistics.median(times[args.jobs])
    print(f"median --jobs 1 {serial:.1f} s, --jobs {args.jobs} {parallel:.1f} s: "
          f"{serial / parallel:.2f}x as fast; rows identical in every run")
    return 0


if __name__ == "__main__":
    sys.exit(main())
