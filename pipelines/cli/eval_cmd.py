"""``gimbaltrack eval``: score a tracker on benchmark sequences (OTB protocol)."""
from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import cv2

from pipelines.batch import BatchError, InputFailed, Outcome, run_batch
from pipelines.cli.batch_options import add_batch_options, batch_jobs
from pipelines.cli.common import CliError, existing_dir, existing_file
from pipelines.outputs.progress import ProgressReporter
from tracker.evaluation import SequenceResult, first_box, run_sequence, summarize
from tracker.evaluation.datasets import GROUNDTRUTH_NAMES, FrameReadError, Sequence, load_sequence
from tracker.runtime.registry import DEFAULT_BACKEND, FALLBACK_BACKEND, available_trackers, make_tracker


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "eval", help="score a tracker on sequences with ground truth (precision@20px, success AUC, fps)",
        description="OTB protocol: initialise on the first ground-truth box, never re-initialise; a lost "
        "subject holds the last box. Frames whose ground truth is NaN or 0,0,0,0 (subject not visible) "
        "are left out of both scores. fps is of the tracking step alone, on one thread (null in --json "
        "when nothing was timed: a one-frame sequence).",
        epilog="examples:\n  gimbaltrack eval ../shared/data/sequences/otb_girl ../shared/data/sequences/vot15_ball1\n"
        "  gimbaltrack eval samples/demo.mp4 --tracker csrt --json\n"
        "  gimbaltrack eval ../shared/data/clips/clip_vot_bag_video/bag.avi "
        "--groundtruth ../shared/data/sequences/vot_bag/groundtruth.txt\n"
        "  gimbaltrack eval ../shared/data/sequences/otb_girl --tracker nanotrack --model-dir ../shared/data/models\n\n"
        "  gimbaltrack eval ../shared/data/sequences/* --jobs 2\n"
        "  gimbaltrack eval ../shared/data/sequences/* --scheduler tcp://scheduler-host:8786 --json\n\n"
        "Rows come in the order the sequences were given, whatever finishes first; --json's summary\n"
        "  names the tracker and its model files (null without).\n"
        "exit status: 0 done; 2 bad input; 130 Ctrl-C (the rows finished are printed, no summary).\n"
        "  Every sequence is checked before the first runs; a frame that cannot be read (a damaged\n"
        "  image, a truncated video) is found only on the way: that sequence is skipped with an error\n"
        "  line, the others are scored and summarised, and the exit status is 2.",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("sequences", nargs="+", metavar="SEQ_DIR",
                        help="OTB/VOT sequence folder, image folder with groundtruth, or video with one beside it")
    parser.add_argument("--groundtruth", type=existing_file, metavar="FILE",
                        help="the ground truth of the one SEQ_DIR given, where it is not in its folder or beside "
                        "its video (OTB x,y,w,h or VOT polygon lines, one per frame)")
    parser.add_argument("--tracker", default="default", metavar="NAME",
                        help=f"one of: {', '.join(available_trackers())} (default: default = "
                        f"{DEFAULT_BACKEND} on the model files shipped with gimbaltrack, or on --model-dir's where it "
                        f"holds them all, or {FALLBACK_BACKEND} where they cannot be loaded)")
    parser.add_argument("--model-dir", type=existing_dir, metavar="DIR",
                        help="folder with optional model files, e.g. NanoTrack's nanotrack_backbone*.onnx and "
                        "nanotrack_head*.onnx, directly or in nanotrack_v2/ (default: the files shipped with gimbaltrack)")
    parser.add_argument("--json", action="store_true", help="one JSON object per sequence, then a summary object")
    add_batch_options(parser, "sequences")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    cv2.setNumThreads(1)
    jobs = batch_jobs(args)
    if args.groundtruth is not None and len(args.sequences) > 1:
        raise CliError(f"--groundtruth is for one sequence, not {len(args.sequences)}: give each its own run")
    sequences = [_load(path, args.groundtruth) for path in args.sequences]
    try:
        probe = make_tracker(args.tracker, args.model_dir)  # bad names and model files: before any run
    except (ValueError, FileNotFoundError) as exc:
        raise CliError(str(exc)) from None
    note = " (skipped; the summary covers the other sequences)" if len(sequences) > 1 else ""

    def show(outcome: Outcome) -> None:
        if outcome.error is None:
            print(json.dumps(outcome.result.as_dict()) if args.json else _row(outcome.result), flush=True)
            return
        if args.debug and outcome.detail:
            print(outcome.detail, file=sys.stderr, end="")
        print(f"gimbaltrack eval: error: {outcome.error}{note}", file=sys.stderr, flush=True)

    outcomes = score_all(sequences, args.tracker, args.model_dir, jobs=jobs, scheduler=args.scheduler, show=show)
    results = [o.result for o in outcomes if o.error is None]
    if results:
        summary = {"tracker": probe.name, "model": probe.model, **summarize(results)}
        print(json.dumps(summary) if args.json else _row_summary(summary))
    return 0 if len(results) == len(sequences) else 2


@dataclass(frozen=True)
class EvalJob:
    """One sequence to score, as handed to a worker (it makes its own tracker)."""

    sequence: Sequence
    tracker: str
    model_dir: Path | None


def score(job: EvalJob, progress: Callable[[int, int], None] | None = None) -> SequenceResult:
    """``job``'s scores with a fresh tracker; ``InputFailed`` naming the frame that cannot be read."""
    try:
        return run_sequence(make_tracker(job.tracker, job.model_dir), job.sequence, progress=progress)
    except FrameReadError as exc:
        raise InputFailed(str(exc)) from None


def score_all(sequences: list[Sequence], tracker: str = "default", model_dir: Path | None = None, *,
              jobs: int = 1, scheduler: str | None = None,
              show: Callable[[Outcome], None] = lambda outcome: None) -> list[Outcome]:
    """Each sequence's outcome (a ``SequenceResult`` or an error line), in their order, run as
    ``pipelines.batch.run_batch`` runs them; one progress line on stderr (per frame when run here,
    per sequence with workers). A scheduler that cannot be used is a ``CliError``."""
    inputs = [(s.name, EvalJob(s, tracker, model_dir)) for s in sequences]
    if scheduler is None and min(jobs, len(inputs)) == 1:
        return run_batch(_scored_with_progress, inputs, show=show)
    reporter = ProgressReporter(sum(len(s) for s in sequences))
    frames = [len(s) for s in sequences]
    done: list[Outcome] = []

    def finished(outcome: Outcome) -> None:
        done.append(outcome)
        reporter.update(sum(frames[o.index] for o in done), f"{len(done)}/{len(inputs)} sequences", force=True)

    try:
        return run_batch(score, inputs, jobs=jobs, scheduler=scheduler, show=show, finished=finished)
    except BatchError as exc:
        raise CliError(str(exc)) from None
    finally:
        reporter.close()


def _scored_with_progress(job: EvalJob) -> SequenceResult:
    """``score`` with a progress bar of the sequence's frames (runs in this process)."""
    reporter = ProgressReporter(len(job.sequence))
    try:
        return score(job, _progress(reporter, job.sequence.name))
    finally:  # also when interrupted, so that a note which follows starts on a line of its own
        reporter.close()


def _load(path: str, groundtruth: Path | None = None) -> Sequence:
    try:
        sequence = load_sequence(path, groundtruth)
    except (ValueError, FileNotFoundError) as exc:
        raise CliError(str(exc)) from None
    if sequence.groundtruth is None:
        names = list(GROUNDTRUTH_NAMES)
        if sequence.video_path is not None:
            stem = sequence.video_path.stem
            names += [f"{stem}.txt", f"{stem}_groundtruth.txt"]
        where = "beside the video" if sequence.video_path is not None else "in the folder"
        raise CliError(f"{path}: no ground truth ({', '.join(names[:-1])} or {names[-1]} {where}; "
                       "or name its file with --groundtruth)")
    try:
        first_box(sequence)
    except ValueError as exc:
        raise CliError(str(exc)) from None
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
    return f"{r.name:24s} frames {r.frames:5d}  prec20 {d['prec20']:.4f}  auc {d['auc']:.4f}  fps {_fps(d['fps'])}"


def _row_summary(s: dict) -> str:
    return (f"{'overall (' + s['tracker'] + ')':24s} seqs {s['sequences']:6d}  prec20 {s['prec20']:.4f}  "
            f"auc {s['auc']:.4f}  fps {_fps(s['fps'])} (median)")


def _fps(fps: float | None) -> str:
    """A rate for the text rows; ``-`` where none was measured (a one-frame sequence)."""
    return f"{'-':>7s}" if fps is None else f"{fps:7.1f}"
