"""Closed-loop centring on the 1280x720 shared sequences: the P baseline vs the PID controller,
with 0 and 100 ms added latency, all measured in this run (real time, simulated gimbal, oracle
detections so the figures isolate the control loop).

    .venv/bin/python benchmarks/bench_closed_loop.py [SEQ_DIR ...]
"""
from __future__ import annotations

import sys
from pathlib import Path

import cv2

from pipelines.closed_loop import LoopSettings, run_closed_loop
from tracker.data_paths import shared_sequences
from tracker.datasets import load_sequence

LATENCIES_MS = (0, 100)
CONTROLLERS = ("p", "pid")
TARGET_RATIO, TARGET_OUT_OF_VIEW = 0.5, 0.02


def wide_sequences() -> list[Path]:
    found = []
    for path in shared_sequences():
        seq = load_sequence(path)
        first = cv2.imread(str(seq.frame_paths[0])) if seq.frame_paths else None
        if seq.groundtruth is not None and first is not None and first.shape[1] >= 1280:
            found.append(path)
    return found


def main(argv: list[str]) -> int:
    sequences = [Path(a) for a in argv] or wide_sequences()
    if not sequences:
        print("no 1280x720 sequence found (set GIMBALTRACK_DATA)")
        return 1
    print(f"{'sequence':<14}{'latency':>8}{'ctrl':>6}{'RMS err':>10}{'mean err':>10}"
          f"{'out of view':>13}{'t centre':>10}{'overshoot':>11}")
    ok = True
    for path in sequences:
        for latency in LATENCIES_MS:
            rms = {}
            for name in CONTROLLERS:
                s = run_closed_loop(path, LoopSettings(controller=name, latency_s=latency / 1000)).summary
                rms[name] = s["rms_center_error"]
                ttc = "never" if s["time_to_first_centre"] is None else f"{s['time_to_first_centre']:.2f} s"
                print(f"{path.name:<14}{latency:>6} ms{name:>6}{s['rms_center_error']:>10.4f}"
                      f"{s['mean_center_error']:>10.4f}{s['out_of_view']:>12.1%}{ttc:>10}{s['overshoot']:>10.0%}")
                if name == "pid":
                    ok &= s["out_of_view"] <= TARGET_OUT_OF_VIEW
            ratio = rms["pid"] / rms["p"]
            ok &= ratio <= TARGET_RATIO
            print(f"{'':<14}{latency:>6} ms  RMS ratio pid/p = {ratio:.2f} (target <= {TARGET_RATIO})")
    print("targets met" if ok else "targets NOT met")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
