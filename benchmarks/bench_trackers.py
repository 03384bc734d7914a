"""Benchmark the project's trackers against OpenCV's own on every shared sequence, in one run.

Prints per-sequence success AUC, mean AUC, mean precision@20px, median fps of the tracking
step (one thread; wall clock, and process CPU time, which the machine's other load affects less),
median fps on the 1280x720 sequences, and ratios against OpenCV's CSRT measured alongside. With
model files, each model also runs as a plain reference loop (the backend alone: no confidence, no
re-acquisition), and each subject tracker is compared with its model's plain loop. Usage:

    .venv/bin/python benchmarks/bench_trackers.py [--model-dir DIR] [--only LABEL]... [--starts] [SEQ ...]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import cv2
import numpy as np

from machine import describe_machine
from tracker.backends import TrackingBackend, make_backend
from tracker.evaluation import PERTURBED_STARTS, SequenceResult, perturbed_box, run_sequence, summarize
from tracker.evaluation.data_paths import shared_data_dir, shared_sequences
from tracker.evaluation.datasets import Sequence, load_sequence
from tracker.runtime.boxes import Box
from tracker.runtime.estimate import TargetEstimate, TrackState
from tracker.runtime.registry import EMBEDDED_MODELS, EMBEDDED_TRACKERS, make_tracker

BASELINE = "opencv-csrt"
ONNX_MODELS = ("nanotrack3", "vittrack", "fear")  # each runs plain and inside the subject tracker
PLAIN = "{} plain loop"
HD = (1280, 720)  # the frame size the fps target is set for


class BareBackend:
    """An OpenCV tracker as it comes: no Kalman, confidence or re-acquisition."""

    def __init__(self, backend: TrackingBackend) -> None:
        self._backend = backend
        self._index = 0

    def init(self, frame: np.ndarray, box: Box, timestamp: float) -> None:
        self._backend.init(frame, box)

    def update(self, frame: np.ndarray, timestamp: float) -> TargetEstimate:
        self._index += 1
        box, score = self._backend.update(frame)
        state = TrackState.LOST if box is None else TrackState.TRACKING
        return TargetEstimate(box or (0.0, 0.0, 0.0, 0.0), (0.0, 0.0), score, state, timestamp, self._index)


def contenders(model_dir: Path | None) -> dict[str, object]:
    """Factories by label: OpenCV's trackers bare, then the project's subject trackers."""
    table = {f"opencv-{n}": (lambda n=n: BareBackend(make_backend(n, model_dir))) for n in ("mil", "kcf", "csrt")}
    table["gimbaltrack csrt-fast"] = lambda: make_tracker("csrt-fast")
    table["dcf backend alone"] = lambda: BareBackend(make_backend("dcf"))
    table["gimbaltrack dcf (no models)"] = lambda: make_tracker("dcf")
    for name in EMBEDDED_TRACKERS:
        table[f"gimbaltrack {name} (embedded model files)"] = lambda name=name: make_tracker(name)
    table[PLAIN.format("nanovit")] = lambda: BareBackend(make_backend("nanovit", EMBEDDED_MODELS))
    if model_dir is not None:
        table["opencv-nano"] = lambda: BareBackend(make_backend("nano", model_dir))
        table["nanotrack backend alone"] = lambda: BareBackend(make_backend("nanotrack", model_dir))
        table["gimbaltrack nanotrack"] = lambda: make_tracker("nanotrack", model_dir)
        for name in ONNX_MODELS:
            table[PLAIN.format(name)] = lambda name=name: BareBackend(make_backend(name, model_dir))
            table[f"gimbaltrack {name}"] = lambda name=name: make_tracker(name, model_dir)
    return table


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    default_models = shared_data_dir() / "models"
    parser.add_argument("--model-dir", type=Path, default=default_models if default_models.is_dir() else None)
    parser.add_argument("--only", action="append", metavar="LABEL",
                        help="a label to run, repeatable (the baseline always runs)")
    parser.add_argument("--baseline", default=BASELINE, metavar="LABEL",
                        help=f"the label the ratios are taken against (default: {BASELINE})")
    parser.add_argument("--starts", action="store_true",
                        help="also track from OTB's perturbed first boxes and print each tracker's mean AUC "
                             "over all starts (steadier than one start)")
    parser.add_argument("sequences", nargs="*", type=Path,
                        help="sequence folders or videos with ground truth (default: every shared sequence)")
    args = parser.parse_args(argv)
    cv2.setNumThreads(1)
    try:
        sequences = [load_sequence(p) for p in (args.sequences or shared_sequences())]
    except (OSError, ValueError) as exc:
        print(f"bench_trackers: {exc}", file=sys.stderr)
        return 2
    if not sequences:
        print(f"no sequences under {shared_data_dir() / 'sequences'}", file=sys.stderr)
        return 2
    table = contenders(args.model_dir)
    if args.baseline not in table:
        print(f"bench_trackers: no tracker labelled {args.baseline!r} (labels: {', '.join(table)})", file=sys.stderr)
        return 2
    labels = [k for k in table if not args.only or k == args.baseline or k in args.only]
    results: dict[str, list[SequenceResult]] = {}
    for label in labels:
        print(f"running {label} ...", file=sys.stderr, flush=True)
        results[label] = [run_sequence(table[label](), seq) for seq in sequences]
    hd = [i for i, seq in enumerate(sequences) if _frame_size(seq) == HD]
    _print_table(results, [s.name for s in sequences], hd, args.baseline)
    _print_against_plain_loops(results)
    if args.starts:
        _print_starts({label: table[label] for label in labels}, sequences, results)
    return 0


def _frame_size(sequence: Sequence) -> tuple[int, int]:
    first = next(iter(sequence.frames()))
    return first.shape[1], first.shape[0]


def _print_against_plain_loops(results: dict[str, list[SequenceResult]]) -> None:
    """Each subject tracker's mean AUC and fps against its model's plain loop, run alongside."""
    for name in ONNX_MODELS:
        ours, plain = results.get(f"gimbaltrack {name}"), results.get(PLAIN.format(name))
        if ours and plain:
            a, b = summarize(ours), summarize(plain)
            print(f"gimbaltrack {name} against its plain loop: AUC {a['auc']:.3f} vs {b['auc']:.3f} "
                  f"({a['auc'] - b['auc']:+.3f}), fps {a['fps']:.0f} vs {b['fps']:.0f} ({a['fps'] / b['fps']:.2f}x)")


def _print_starts(table: dict[str, object], sequences: list[Sequence],
                  results: dict[str, list[SequenceResult]]) -> None:
    """Mean AUC per sequence over the given start and ``PERTURBED_STARTS``."""
    print(f"\nmean AUC over {1 + len(PERTURBED_STARTS)} starts (the first box, then shifted/scaled):")
    print(f"| tracker | {' | '.join(s.name.split('_', 1)[-1][:8] for s in sequences)} | mean |")
    print("|---" * (len(sequences) + 2) + "|")
    for label, factory in table.items():
        print(f"running {label} from perturbed starts ...", file=sys.stderr, flush=True)
        means = []
        for seq, first in zip(sequences, results[label]):
            aucs = [first.auc] + [run_sequence(factory(), seq, start=perturbed_box(seq.groundtruth[0], *p)).auc
                                  for p in PERTURBED_STARTS]
            means.append(float(np.mean(aucs)))
        print(f"| {label} | {' | '.join(f'{m:.2f}' for m in means)} | {np.mean(means):.3f} |", flush=True)


def _print_table(results: dict[str, list[SequenceResult]], names: list[str], hd: list[int], baseline: str) -> None:
    """One row per tracker: AUC per sequence, means, fps (all, and on the 1280x720 sequences ``hd``),
    and ratios against ``baseline``."""
    print(describe_machine())
    base = summarize(results[baseline])
    short = [n.split("_", 1)[-1][:8] for n in names]
    print(f"ratios against: {baseline}")
    print(f"| tracker | {' | '.join(short)} | mean AUC | mean prec20 | median fps | median fps 1280x720 "
          "| AUC ratio | fps ratio | median CPU fps | CPU fps ratio |")
    print("|---" * (len(names) + 9) + "|")
    for label, rows in results.items():
        s = summarize(rows)
        cells = " | ".join(f"{r.auc:.2f}" for r in rows)
        hd_fps = float(np.median([rows[i].fps for i in hd])) if hd else float("nan")
        print(f"| {label} | {cells} | {s['auc']:.3f} | {s['prec20']:.3f} | {s['fps']:.0f} | {hd_fps:.0f} "
              f"| {s['auc'] / base['auc']:.2f} | {s['fps'] / base['fps']:.2f} | {s['cpu_fps']:.0f} "
              f"| {s['cpu_fps'] / base['cpu_fps']:.2f} |")


if __name__ == "__main__":
    sys.exit(main())
