"""Throughput of the whole ``gimbaltrack track`` loop on 1280x720 video, against decode alone.

Encodes the shared vot15_ball1 frames (1280x720) to an H.264 (or MPEG-4) clip in a temporary folder (looped
to ``--loops`` passes; never written into the project), or, when the shared data is absent,
upscales samples/demo.mp4 to 1280x720. Then, in one run on the same file:

- decode only: ``cv2.VideoCapture.read`` over every frame;
- the loop (default tracker, built-in simulated gimbal) without and with the annotated video.

Prints frames/s, the loop/decode ratios and per-frame loop times (from the telemetry's ``t_run``).
Targets: loop >= 50 % of decode speed; per-frame p99 under 33.3 ms (30 fps never lost).

    .venv/bin/python benchmarks/bench_pipeline.py [--loops 3] [--codec h264|mpeg4] [--profile]
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

from pipelines.cli import main  # noqa: E402
from pipelines.outputs.telemetry import read_telemetry  # noqa: E402
from tracker.data_paths import shared_data_dir  # noqa: E402

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


def main_bench() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--loops", type=int, default=3, help="passes over the 105 ball1 frames (default 3)")
    parser.add_argument("--profile", action="store_true", help="cProfile both loop runs")
    parser.add_argument("--codec", choices=CODECS, default="h264",
                        help="how the clip is encoded: h264 (default) is what cameras and phones record; "
                             "mpeg4 decodes twice as fast")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench_pipeline_") as tmp:
        folder = Path(tmp)
        clip, roi, origin = make_clip(folder, args.loops, args.codec)
        decode, frames = decode_fps(clip)
        print(f"clip: {origin}, {frames} frames 1280x720 {args.codec}, subject {roi}, cv2 threads {cv2.getNumThreads()}")
        print(f"{'run':<28}{'fps':>8}{'x decode':>10}{'p50 ms':>9}{'p95 ms':>9}{'p99 ms':>9}{'max ms':>9}")
        print(f"{'decode only':<28}{decode:8.1f}{1.0:10.2f}")
        for video in (False, True):
            fps, per_frame = track(clip, folder / f"out{int(video)}", roi, video, args.profile)
            p50, p95, p99 = np.percentile(per_frame, [50, 95, 99])
            name = "track + annotated video" if video else "track, no video"
            print(f"{name:<28}{fps:8.1f}{fps / decode:10.2f}{p50:9.1f}{p95:9.1f}{p99:9.1f}{per_frame.max():9.1f}"
                  f"  ratio target >= 0.50: {'met' if fps / decode >= 0.5 else 'MISSED'}; "
                  f"real time (p99 <= {REALTIME_MS:.1f} ms): {'kept' if p99 <= REALTIME_MS else 'LOST'}")


if __name__ == "__main__":
    main_bench()
