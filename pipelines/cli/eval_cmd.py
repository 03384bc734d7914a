"""``gimbaltrack eval``: score a tracker on benchmark sequences (OTB protocol)."""
from __future__ import annotations

import argparse
import json
from collections.abc import Callable

import cv2

from pipelines.cli.common import CliError
from pipelines.progress import ProgressReporter
from tracker.datasets import load_sequence
from tracker.evaluation import SequenceResult, run_sequence, summarize
from tracker.registry import available_trackers, make_tracker


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "eval", help="score a tracker on sequences with ground truth (precision@20px, success AUC, fps)",
        description="OTB protocol: initialise on the first ground-truth box, never re-initialise; a lost "
        "subject holds the last box. fps is of the tracking step alone, on one thread.")
    parser.add_argument("sequences", nargs="+", metavar="SEQ_DIR",
                        help="OTB/VOT sequence folder, image folder with groundtruth, or video with one beside it")
    parser.add_argument("--tracker", default="default", help=f"one of: {', '.join(available_trackers())}")
    parser.add_argument("--model-dir", help="folder with optional model files (e.g. NanoTrack ONNX)")
    parser.add_argument("--json", action="store_true", help="one JSON object per sequence, then a summary object")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    cv2.setNumThreads(1)
    sequences = [_load(path) for path in args.sequences]
    results: list[SequenceResult] = []
    for sequence in sequences:
        try:
            subject = make_tracker(args.tracker, args.model_dir)
        except (ValueError, FileNotFoundError) as exc:
            raise CliError(str(exc)) from None
        result = run_sequence(subject, sequence, progress=_progress(sequence.name))
        results.append(result)
        print(json.dumps(result.as_dict()) if args.json else _row(result), flush=True)
    summary = {"tracker": subject.name, **summarize(results)}
    print(json.dumps(summary) if args.json else _row_summary(summary))
    return 0


def _load(path: str):
    try:
        sequence = load_sequence(path)
    except (ValueError, FileNotFoundError) as exc:
        raise CliError(str(exc)) from None
    if sequence.groundtruth is None:
        raise CliError(f"{path}: no ground truth (groundtruth_rect.txt or groundtruth.txt)")
    return sequence


def _progress(name: str) -> Callable[[int, int], None]:
    """A progress callback for one sequence, drawn by the shared ProgressReporter on stderr."""
    reporter: ProgressReporter | None = None

    def report(done: int, total: int) -> None:
        nonlocal reporter
        reporter = reporter or ProgressReporter(total)
        reporter.update(done, name, force=done == total)
        if done == total:
            reporter.close()
    return report


def _row(r: SequenceResult) -> str:
    return f"{r.name:24s} frames {r.frames:5d}  prec20 {r.prec20:.3f}  auc {r.auc:.3f}  fps {r.fps:7.1f}"


def _row_summary(s: dict) -> str:
    return (f"{'overall (' + s['tracker'] + ')':24s} seqs {s['sequences']:6d}  prec20 {s['prec20']:.3f}  "
            f"auc {s['auc']:.3f}  fps {s['fps']:7.1f} (median)")
