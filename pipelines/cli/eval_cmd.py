"""``gimbaltrack eval``: score a tracker on benchmark sequences (OTB protocol)."""
from __future__ import annotations

import argparse
import json
from collections.abc import Callable

import cv2

from pipelines.cli.common import CliError, existing_dir
from pipelines.progress import ProgressReporter
from tracker.datasets import GROUNDTRUTH_NAMES, Sequence, load_sequence
from tracker.evaluation import SequenceResult, run_sequence, summarize
from tracker.registry import DEFAULT_BACKEND, DEFAULT_WITH_MODELS, available_trackers, make_tracker


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "eval", help="score a tracker on sequences with ground truth (precision@20px, success AUC, fps)",
        description="OTB protocol: initialise on the first ground-truth box, never re-initialise; a lost "
        "subject holds the last box. fps is of the tracking step alone, on one thread.",
        epilog="examples:\n  gimbaltrack eval ../shared/data/sequences/otb_girl ../shared/data/sequences/vot15_ball1\n"
        "  gimbaltrack eval samples/demo.mp4 --tracker csrt --json\n"
        "  gimbaltrack eval ../shared/data/sequences/otb_girl --tracker nanotrack --model-dir ../shared/data/models",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("sequences", nargs="+", metavar="SEQ_DIR",
                        help="OTB/VOT sequence folder, image folder with groundtruth, or video with one beside it")
    parser.add_argument("--tracker", default="default", metavar="NAME",
                        help=f"one of: {', '.join(available_trackers())} (default: default = "
                        f"{DEFAULT_WITH_MODELS} when --model-dir holds its files, else {DEFAULT_BACKEND})")
    parser.add_argument("--model-dir", type=existing_dir, metavar="DIR",
                        help="folder with optional model files, e.g. NanoTrack's nanotrack_backbone*.onnx and "
                        "nanotrack_head*.onnx, directly or in nanotrack_v2/ (default: none)")
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
        reporter = ProgressReporter(len(sequence))
        try:
            result = run_sequence(subject, sequence, progress=_progress(reporter, sequence.name))
        finally:  # also when interrupted, so that the note which follows starts on a line of its own
            reporter.close()
        results.append(result)
        print(json.dumps(result.as_dict()) if args.json else _row(result), flush=True)
    summary = {"tracker": subject.name, **summarize(results)}
    print(json.dumps(summary) if args.json else _row_summary(summary))
    return 0


def _load(path: str) -> Sequence:
    try:
        sequence = load_sequence(path)
    except (ValueError, FileNotFoundError) as exc:
        raise CliError(str(exc)) from None
    if sequence.groundtruth is None:
        names = list(GROUNDTRUTH_NAMES)
        if sequence.video_path is not None:
            stem = sequence.video_path.stem
            names += [f"{stem}.txt", f"{stem}_groundtruth.txt"]
        where = "beside the video" if sequence.video_path is not None else "in the folder"
        raise CliError(f"{path}: no ground truth ({', '.join(names[:-1])} or {names[-1]} {where})")
    return sequence


def _progress(reporter: ProgressReporter, name: str) -> Callable[[int, int], None]:
    """A ``run_sequence`` progress callback drawing on the shared ProgressReporter (stderr)."""
    def report(done: int, total: int) -> None:
        reporter.update(done, name, force=done == total)
    return report


# Text rows print the numbers the JSON holds (4 decimals), so a sequence and an overall of the same
# value read the same.
def _row(r: SequenceResult) -> str:
    d = r.as_dict()
    return f"{r.name:24s} frames {r.frames:5d}  prec20 {d['prec20']:.4f}  auc {d['auc']:.4f}  fps {d['fps']:7.1f}"


def _row_summary(s: dict) -> str:
    return (f"{'overall (' + s['tracker'] + ')':24s} seqs {s['sequences']:6d}  prec20 {s['prec20']:.4f}  "
            f"auc {s['auc']:.4f}  fps {s['fps']:7.1f} (median)")
