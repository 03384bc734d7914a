"""Closed-loop centring on every shared sequence: the P baseline vs the PID controller, with 0 and
100 ms added latency, all measured in this run (real time, simulated gimbal, oracle detections so
the figures isolate the control loop). The view is half the recording's size at its focal length
(the central half at rest, as 640x360 in 1280x720), and the gimbal starts pointed at the first box.

    .venv/bin/python benchmarks/bench_closed_loop.py [--fps FPS] [SEQ_DIR ...]
    .venv/bin/python benchmarks/bench_closed_loop.py --bounds [SEQ_DIR ...]

``fps kept`` is the capture rate the run achieved (frames over the capture times' span): below the
asked rate, the machine could not keep up and the figures are for a slower loop.

``--bounds`` prints, instead, two lower bounds on the RMS centring error of ANY controller
(offline, no simulator), per latency:
- information: the pointing at frame k can only depend on frames processed before it, i.e.
  frames <= k - m (m = 1 at 0 ms, 4 at 100 ms with 30 fps and ~4 ms processing); so its error is
  at least the error of predicting frame k from them. Shown: the best of standard predictors
  (hold the last direction, constant-velocity Kalman at several noise levels), without any
  acceleration limit. Not a proof over all predictors, the best of the usual ones.
- acceleration: the best error with the WHOLE future known, at the simulator's 720 deg/s^2 per
  axis and at the controller's own configured limit, starting at rest and not moving before the
  first frame is processed (bounded least squares over the axes' accelerations; scipy, which
  filterpy already requires).
"""
from __future__ import annotations

import argparse
import functools
import math
import statistics
import sys
from pathlib import Path

import cv2
import numpy as np

from gimbal.errors import GimbalError
from gimbal.sim import SimConfig
from machine import describe_machine
from pipelines.control.controller import ControlConfig
from pipelines.control.direction import DirectionFilter
from pipelines.loop.closed_loop import LoopSettings, run_closed_loop
from pipelines.sources.virtual_camera import VirtualCamera
from tracker.evaluation.data_paths import shared_sequences
from tracker.evaluation.datasets import Sequence, load_sequence
from tracker.evaluation.metrics import has_truth
from tracker.runtime.boxes import center

LATENCIES_MS = (0, 100)
CONTROLLERS = ("p", "pid")
TARGET_RATIO, TARGET_OUT_OF_VIEW = 0.5, 0.02


@functools.cache
def _load(path: Path) -> tuple[Sequence, tuple[int, int] | None]:
    """The sequence and its frame size (width, height), its first image read once per run."""
    seq = load_sequence(path)
    first = cv2.imread(str(seq.frame_paths[0])) if seq.frame_paths else None
    return seq, None if first is None else (first.shape[1], first.shape[0])


def sequences_with_truth() -> list[Path]:
    """Every shared sequence that has ground truth and a readable first frame."""
    found = []
    for path in shared_sequences():
        seq, size = _load(path)
        if seq.groundtruth is not None and size is not None:
            found.append(path)
    return found


def view_size(path: Path) -> tuple[int, int]:
    """Half the recording's size (even numbers of pixels)."""
    _, (width, height) = _load(path)
    return max(2, width // 4 * 2), max(2, height // 4 * 2)


def _truth_angles(path: Path) -> tuple[np.ndarray, float]:
    """World (yaw, pitch) of the subject's centre per frame (NaN where the frame has no ground
    truth), and degrees -> diagonal fraction."""
    seq, size = _load(path)
    vc = VirtualCamera(size, view_size(path))
    angles = np.array([vc.source.pixel_to_angles(*center(box)) if has_truth(box) else (math.nan, math.nan)
                       for box in seq.groundtruth])
    return angles, math.radians(1.0) * vc.camera.focal_px / vc.camera.diagonal_px


def _prediction_rms(angles: np.ndarray, ahead: int, predictor: str, accel_std: float, fps: float) -> float:
    """RMS error (deg) of predicting frame k from frames <= k - ahead (before any: the start, 0),
    over the frames with ground truth."""
    kf, errs, state = DirectionFilter(accel_std_dps2=accel_std), [], None
    for k in range(len(angles)):
        if k - ahead >= 0 and not np.isnan(angles[k - ahead]).any():
            state = kf.update(tuple(angles[k - ahead]), (k - ahead) / fps)
        guess = (0.0, 0.0) if state is None else (
            (state.yaw, state.pitch) if predictor == "hold" else state.at(k / fps))
        errs.append(math.hypot(*(np.asarray(guess) - angles[k])))
    return float(np.sqrt(np.nanmean(np.square(errs))))


def _accel_bound(angles: np.ndarray, start_s: float, accel: float, fps: float, sub: int = 4) -> float:
    """RMS angle error (deg) of the best trajectory from rest with |accel| <= accel per
    axis, not moving before ``start_s``, knowing the whole future."""
    from scipy.optimize import lsq_linear
    n, h = len(angles), 1.0 / fps / sub
    a = np.zeros((n, n * sub))
    for k in range(n):
        j = np.arange(k * sub)
        a[k, j] = h * (k / fps - (j + 0.5) * h)
    a[:, : round(start_s / h)] = 0.0
    known = ~np.isnan(angles).any(axis=1)
    a, angles = a[known], angles[known]
    err = [a @ lsq_linear(a, angles[:, i], bounds=(-accel, accel), method="bvls").x - angles[:, i]
           for i in (0, 1)]
    return float(np.sqrt(np.mean(np.square(err[0]) + np.square(err[1]))))


def bounds(sequences: list[Path], fps: float = 30.0, processing_s: float = 0.004) -> None:
    accel, own = SimConfig().accel_dps2, ControlConfig().max_accel_dps2
    for path in sequences:
        angles, to_diag = _truth_angles(path)
        for latency in LATENCIES_MS:
            ahead = math.floor((latency / 1000 + processing_s) * fps) + 1
            preds = {f"{p} (accel std {s:g})": _prediction_rms(angles, ahead, p, s, fps) * to_diag
                     for p in ("hold", "cv") for s in (30.0, 100.0, 300.0, 1000.0)}
            best = min(preds, key=preds.get)
            acc = [_accel_bound(angles, latency / 1000 + processing_s, a, fps) * to_diag for a in (accel, own)]
            print(f"{path.name:<14}{latency:>6} ms  information bound (frames <= k-{ahead}): "
                  f"{preds[best]:.4f} [{best}]  acceleration bound (future known): {acc[0]:.4f} at the "
                  f"simulator's {accel:g} deg/s^2, {acc[1]:.4f} at the configured {own:g}")


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bounds", action="store_true", help="print the lower bounds instead")
    parser.add_argument("--fps", type=float, default=30.0, help="playback frame rate (default 30)")
    parser.add_argument("sequences", nargs="*", type=Path, help="default: every shared sequence")
    args = parser.parse_args(argv)
    sequences = args.sequences or sequences_with_truth()
    if not sequences:
        print("no shared sequence found (set GIMBALTRACK_DATA)")
        return 1
    if args.bounds:
        bounds(sequences, fps=args.fps)
        return 0
    print(describe_machine())
    print(f"{'sequence':<20}{'latency':>8}{'ctrl':>6}{'RMS err':>10}{'mean err':>10}"
          f"{'out of view':>13}{'t centre':>10}{'overshoot':>11}{'fps kept':>10}")
    ok = True
    rms_all: dict[tuple[int, str], list[float]] = {}
    out_all: dict[tuple[int, str], list[float]] = {}
    for path in sequences:
        for latency in LATENCIES_MS:
            rms = {}
            for name in CONTROLLERS:
                try:
                    result = run_closed_loop(path, LoopSettings(controller=name, latency_s=latency / 1000,
                                                                out_size=view_size(path), fps=args.fps))
                except GimbalError as exc:  # the simulator starved of CPU on a loaded machine
                    print(f"{path.name:<20}{latency:>6} ms{name:>6}  failed: {exc}", flush=True)
                    ok = False
                    continue
                s = result.summary
                span = result.steps[-1].t - result.steps[0].t
                kept = (len(result.steps) - 1) / span if span > 0 else math.nan
                rms[name] = s["rms_center_error"]
                rms_all.setdefault((latency, name), []).append(s["rms_center_error"])
                out_all.setdefault((latency, name), []).append(s["out_of_view"])
                ttc = "never" if s["time_to_first_centre"] is None else f"{s['time_to_first_centre']:.2f} s"
                print(f"{path.name:<20}{latency:>6} ms{name:>6}{s['rms_center_error']:>10.4f}"
                      f"{s['mean_center_error']:>10.4f}{s['out_of_view']:>12.1%}{ttc:>10}{s['overshoot']:>10.0%}"
                      f"{kept:>10.1f}", flush=True)
                if name == "pid":
                    ok &= s["out_of_view"] <= TARGET_OUT_OF_VIEW
            if len(rms) == len(CONTROLLERS):
                ratio = rms["pid"] / rms["p"]
                ok &= ratio <= TARGET_RATIO
                print(f"{'':<20}{latency:>6} ms  RMS ratio pid/p = {ratio:.2f} (target <= {TARGET_RATIO})")
    print(f"\nmeans over the runs that finished ({len(sequences)} sequences) at {args.fps:g} fps:")
    for latency in LATENCIES_MS:
        if any((latency, name) not in rms_all for name in CONTROLLERS):
            continue
        p, pid = (statistics.fmean(rms_all[latency, name]) for name in CONTROLLERS)
        print(f"{latency:>6} ms  RMS p {p:.4f}, pid {pid:.4f} (ratio {pid / p:.2f}); out of view "
              f"p {statistics.fmean(out_all[latency, 'p']):.1%}, pid {statistics.fmean(out_all[latency, 'pid']):.1%}"
              f" (worst sequence {max(out_all[latency, 'pid']):.1%})")
    print("targets met" if ok else "targets NOT met")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
