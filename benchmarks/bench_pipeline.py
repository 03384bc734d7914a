"""Throughput of the whole ``gimbaltrack track`` loop on 1280x720 video, against decode alone.

Encodes the shared vot15_ball1 frames (1280x720) to an H.264 (or MPEG-4) clip in a temporary folder (looped
to ``--loops`` passes; never written into the project), or, when the shared data is absent,
upscales samples/demo.mp4 to 1280x720. Then, in one run on the same file:

- decode only: ``cv2.VideoCapture.read`` over every frame;
- the loop (default tracker, built-in simulated gimbal) without and with the annotated video.

The three runs are repeated in ``--rounds`` interleaved rounds: this machine's speed changes from
one second to the next, so a single decode-only run is not a baseline to trust. Prints each
round, then the median frames/s of each run, the ratio of the medians (and the range of the
per-round ratios) and per-frame loop times over all rounds (from the telemetry's ``t_run``).
Targets: loop >= 50 % of decode speed; per-frame p99 under 33.3 ms (30 fps never lost).

    .venv/bin/python benchmarks/bench_pipeline.py [--loops 3] [--rounds 5] [--codec h264|mpeg4] [--profile]
"""
from __future__ import annotations

import argparse
import contextlib
import cProfile
import io
import pstats
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from machine import describe_machine  # noqa: E402
from pipelines.cli import main  # noqa: E402
from pipelines.outputs.telemetry import read_telemetry  # noqa: E402
from tracker.evaluation.data_paths import shared_data_dir  # noqa: E402

REALTIME_MS = 1000.0 / 30.0


CODECS = {"mpeg4": ["-c:v", "mpeg4", "-q:v", "3"],
          "h264": ["-c:v", "libx264", "-preset", "medium", "-crf", "20", "-pix_fmt", "yuv420p"]}


def make_clip(folder: Path, loops: int, codec: str) -> tuple[Path, str, str]:
    """(the 1280x720 clip, the first frame's subject box as x,y,w,h, where it came from)."""
    ffmpeg = shutil.which("ffmpeg")
    if ffmpeg is None:
        sys.exit("bench_pipeline: ffmpeg is needed to make the 1280x720 clip")
    clip = folder / "clip720.mp4"
    ball = shared_data_dir() / "sequences" / "vot15_ball1"
    if (ball / "imgs").is_dir():
        points = np.array([float(v) for v in (ball / "groundtruth.txt").read_text().splitlines()[0].split(",")])
        xs, ys = points[0::2], points[1::2]
        roi = f"{xs.min():.0f},{ys.min():.0f},{xs.max() - xs.min():.0f},{ys.max() - ys.min():.0f}"
        source = ["-stream_loop", str(loops - 1), "-framerate", "30", "-i", str(ball / "imgs" / "%08d.jpg")]
        origin = f"shared vot15_ball1 frames x{loops}"
    else:
        roi = ",".join(str(round(int(v) * 2)) for v in (ROOT / "samples/demo_roi.txt").read_text().split(","))
        source = ["-i", str(ROOT / "samples" / "demo.mp4"), "-vf", "scale=1280:720"]
        origin = "samples/demo.mp4 upscaled to 1280x720 (shared data absent)"
    subprocess.run([ffmpeg, "-loglevel", "error", "-y", *source, *CODECS[codec], str(clip)], check=True)
    return clip, roi, origin


def decode_fps(clip: Path) -> tuple[float, int]:
    capture = cv2.VideoCapture(str(clip))
    frames, start = 0, time.perf_counter()
    while capture.read()[0]:
        frames += 1
    elapsed = time.perf_counter() - start
    capture.release()
    return frames / elapsed, frames


def track(clip: Path, out: Path, roi: str, video: bool, profile: bool) -> tuple[float, np.ndarray]:
    """The loop's frames/s and per-frame times (ms) from its telemetry."""
    args = ["track", str(clip), "--out", str(out), "--quiet", "--roi", roi] + ([] if video else ["--no-video"])
    profiler = cProfile.Profile() if profile else None
    with contextlib.redirect_stdout(io.StringIO()):
        if profiler:
            profiler.enable()
        code = main(args)
        if profiler:
            profiler.disable()
    if code != 0:
        sys.exit(f"bench_pipeline: track exited {code}")
    if profiler:
        stats = pstats.Stats(profiler, stream=sys.stdout)
        print(f"--- profile, {'with' if video else 'without'} video (cumulative, top 25)")
        stats.sort_stats("cumulative").print_stats(25)
    t = np.array([r["t_run"] for r in read_telemetry(out / "telemetry.jsonl")])
    per_frame = np.diff(t) * 1000.0
    return (len(t) - 1) / (t[-1] - t[0]), per_frame


RUNS = {"decode only": None, "track, no video": False, "track + annotated video": True}


def main_bench() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--loops", type=int, default=3, help="passes over the 105 ball1 frames (default 3)")
    parser.add_argument("--rounds", type=int, default=5,
                        help="rounds of the three runs, interleaved so that each ratio compares runs made "
                             "moments apart on this shared machine (default 5)")
    parser.add_argument("--profile", action="store_true", help="cProfile both loop runs")
    parser.add_argument("--codec", choices=CODECS, default="h264",
                        help="how the clip is encoded: h264 (default) is what cameras and phones record; "
                             "mpeg4 decodes twice as fast")
    args = parser.parse_args()
    if args.loops < 1 or args.rounds < 1:
        parser.error("--loops and --rounds must be at least 1")
    with tempfile.TemporaryDirectory(prefix="bench_pipeline_") as tmp:
        folder = Path(tmp)
        clip, roi, origin = make_clip(folder, args.loops, args.codec)
        fps: dict[str, list[float]] = {name: [] for name in RUNS}
        times: dict[str, list[np.ndarray]] = {name: [] for name in RUNS}
        for round_ in range(1, args.rounds + 1):
            for name, video in RUNS.items():
                if video is None:
                    rate, frames = decode_fps(clip)
                else:
                    rate, per_frame = track(clip, folder / f"out{int(video)}", roi, video, args.profile)
                    times[name].append(per_frame)
                fps[name].append(rate)
            print(f"round {round_}: " + ", ".join(f"{name} {values[-1]:.0f} fps" for name, values in fps.items()),
                  flush=True)
        print(describe_machine())
        print(f"clip: {origin}, {frames} frames 1280x720 {args.codec}, subject {roi}, "
              f"cv2 threads {cv2.getNumThreads()}, {args.rounds} rounds")
        print(f"{'run':<28}{'median fps':>11}{'x decode':>10}{'per round':>14}{'p50 ms':>9}{'p95 ms':>9}"
              f"{'p99 ms':>9}{'max ms':>9}")
        decode = np.array(fps["decode only"])
        print(f"{'decode only':<28}{np.median(decode):11.1f}{1.0:10.2f}")
        for name in list(RUNS)[1:]:
            ratios = np.array(fps[name]) / decode
            ratio = float(np.median(fps[name]) / np.median(decode))
            per_frame = np.concatenate(times[name])
            p50, p95, p99 = np.percentile(per_frame, [50, 95, 99])
            print(f"{name:<28}{np.median(fps[name]):11.1f}{ratio:10.2f}{ratios.min():8.2f}-{ratios.max():.2f}"
                  f"{p50:9.1f}{p95:9.1f}{p99:9.1f}{per_frame.max():9.1f}"
                  f"  ratio target >= 0.50: {'met' if ratio >= 0.5 else 'MISSED'}; "
                  f"real time (p99 <= {REALTIME_MS:.1f} ms): {'kept' if p99 <= REALTIME_MS else 'LOST'}")


if __name__ == "__main__":
    main_bench()
