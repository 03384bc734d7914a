"""``gimbaltrack simulate``: the closed loop on a recorded sequence against the simulated gimbal."""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pipelines.cli.common import CliError, existing_dir, make_out_dir, out_dir
from pipelines.control.controller import controller_names
from pipelines.control.metrics import MAX_ERROR, OVERSHOOT_WINDOW_S
from pipelines.loop.closed_loop import ORACLE, LoopResult, LoopSettings, PreparedLoop, prepare_loop, run_prepared
from pipelines.outputs.latency import latency_percentiles
from pipelines.outputs.progress import ProgressReporter
from pipelines.outputs.summary import write_summary
from tracker.runtime.registry import DEFAULT_BACKEND, FALLBACK_BACKEND, available_trackers

if TYPE_CHECKING:
    from pipelines.loop import FrameRecord


MAX_LATENCY_MS = 2000.0  # far beyond any pipeline worth simulating; a typo must not sleep for hours
MAX_FPS = 1000.0
MAX_SIDE = 8192  # pixels a side of the view: beyond 8K video, and a typo must not allocate gigabytes a frame


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "simulate", help="run tracker + control + client against the simulated gimbal on a sequence",
        description="Play SEQ_DIR (frames or a video with ground truth) through a narrower virtual "
        "camera mounted on the simulated gimbal (python-can virtual bus, simulator in-process), in "
        "real time, and report how well the subject stays centred. Frames without ground truth "
        "(NaN or empty boxes) are left out of the scores and are no detection for --tracker oracle.",
        epilog="examples:\n  gimbaltrack simulate ../shared/data/sequences/vot15_ball1\n"
        "  gimbaltrack simulate ../shared/data/sequences/vot15_ball1 --tracker oracle --latency 100 --out /tmp/sim\n"
        "  gimbaltrack simulate samples/demo_wide.mp4 --out out/demo   (what scripts/demo.sh runs)\n\n"
        "outputs in --out: annotated.avi (the view), telemetry.jsonl, can.log, summary.json, plot.png",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("sequence", metavar="SEQ_DIR", help="sequence folder or video with ground truth")
    parser.add_argument("--fov", type=float, metavar="DEG",
                        help="horizontal field of view of the view (default: crop-equivalent, the "
                        "recording's focal length)")
    parser.add_argument("--size", type=_size, default=(640, 360), metavar="WxH",
                        help="view size in pixels (default 640x360)")
    parser.add_argument("--latency", type=float, default=0.0, metavar="MS",
                        help="added latency between capture and tracking (default 0)")
    parser.add_argument("--controller", choices=controller_names(), default="pid",
                        help="pid (default: world-frame PID + feed-forward + latency compensation) "
                        "or p (speed proportional to pixel error, the public-driver baseline)")
    parser.add_argument("--tracker", default="default", choices=[ORACLE, *available_trackers()], metavar="NAME",
                        help=f"one of: {', '.join(available_trackers())} (default: default = "
                        f"{DEFAULT_BACKEND} on the model files shipped with gimbaltrack, or on --model-dir's where it "
                        f"holds them all, or {FALLBACK_BACKEND} where they cannot be loaded), "
                        f"or {ORACLE}: the ground-truth box is the detection, isolating the control loop")
    parser.add_argument("--model-dir", type=existing_dir, metavar="DIR",
                        help="folder with optional model files, e.g. NanoTrack's nanotrack_backbone*.onnx and "
                        "nanotrack_head*.onnx, directly or in nanotrack_v2/ (default: the files shipped with gimbaltrack)")
    parser.add_argument("--fps", type=float, default=30.0, help="playback frame rate (default 30)")
    parser.add_argument("--max-frames", type=int, metavar="N", help="stop after N frames (default: all)")
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of text")
    parser.add_argument("--quiet", action="store_true", help="no progress line (shown on a terminal only)")
    parser.add_argument("--out", type=out_dir, metavar="DIR",
                        help="write the view's annotated video, telemetry, CAN log, plot.png and summary.json "
                        "here, as track does (default: none, nothing is written)")
    parser.set_defaults(func=run)


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WxH, got {text!r}") from None
    if w <= 0 or h <= 0:
        raise argparse.ArgumentTypeError(f"size must be positive, got {text!r}")
    return w, h


class _CountedFrames:
    """A prepared loop's frames, counted on a progress line as the run takes them, as ``track``
    shows its own (the loop runs in real time: a long sequence takes minutes)."""

    def __init__(self, frames: Iterator[np.ndarray], progress: ProgressReporter) -> None:
        self._frames = frames
        self._progress = progress
        self.taken = 1  # prepare_loop read the first

    def __iter__(self) -> Iterator[np.ndarray]:
        return self

    def __next__(self) -> np.ndarray:
        self._progress.update(self.taken)
        frame = next(self._frames)
        self.taken += 1
        return frame

    def close(self, status: str) -> None:
        self._progress.update(self.taken, status, force=True)
        self._progress.close()


def summary_of(result: LoopResult) -> dict[str, object]:
    s = result.settings
    median = latency_percentiles(result.command_latencies)["p50"]
    return {
        **result.summary,
        "controller": s.controller, "tracker": s.tracker, "latency_ms": s.latency_s * 1000.0,
        "fov_deg": s.hfov_deg, "size": list(s.out_size), "loop": "closed",
        "median_capture_to_bus_ms": None if median is None else median * 1000.0,
    }


class Outputs:
    """What ``--out`` gets, of the same kind as ``track``'s: the view's annotated video, telemetry,
    the CAN log, and plot.png (the angular error and rates, and the centring error against the
    ground truth) as the run goes; summary.json at the end."""

    def __init__(self, out: Path, loop: PreparedLoop) -> None:
        from pipelines.loop import Panel, PlotSink, TelemetrySink, VideoSink, loop_panels
        from pipelines.outputs.can_log import CanLogWriter
        samples = loop.samples

        def centre_error(record: FrameRecord) -> float:
            sample = samples.get(record.index)
            return math.nan if sample is None else sample.error

        self.paths = {name: out / name for name in
                      ("annotated.avi", "telemetry.jsonl", "can.log", "plot.png", "summary.json")}
        truth = Panel("centring error against the ground truth", "fraction of diagonal",
                      {"centre error": centre_error})
        self.can_log = CanLogWriter(self.paths["can.log"])
        self.sinks = [TelemetrySink(self.paths["telemetry.jsonl"]),
                      PlotSink(self.paths["plot.png"], (*loop_panels(True), truth)),
                      VideoSink(self.paths["annotated.avi"], loop.settings.out_size, loop.settings.fps, None)]

    def stop(self) -> None:
        self.can_log.stop()
        if self.can_log.error is not None:
            raise OSError(self.can_log.error)


def run(args: argparse.Namespace) -> int:
    if not 0 <= args.latency <= MAX_LATENCY_MS or not 0 < args.fps <= MAX_FPS:
        raise CliError(f"--latency takes 0 to {MAX_LATENCY_MS:g} ms and --fps above 0 up to {MAX_FPS:g}")
    if args.fov is not None and not 0 < args.fov < 180:
        raise CliError(f"--fov takes 0 < DEG < 180, not {args.fov:g}")
    if args.max_frames is not None and args.max_frames < 1:
        raise CliError("--max-frames must be at least 1")
    if max(args.size) > MAX_SIDE:
        raise CliError(f"--size takes at most {MAX_SIDE} pixels a side, not {args.size[0]}x{args.size[1]}")
    settings = LoopSettings(controller=args.controller, tracker=args.tracker, hfov_deg=args.fov,
                            out_size=args.size, latency_s=args.latency / 1000.0, fps=args.fps,
                            model_dir=args.model_dir, max_frames=args.max_frames)
    outputs = None
    try:
        loop = prepare_loop(args.sequence, settings)  # a bad sequence fails before --out is created
        if args.out:
            make_out_dir(args.out)
            outputs = Outputs(args.out, loop)  # shares the loop's samples, as the copy below does
        frames = _CountedFrames(loop.frames, ProgressReporter(min(len(loop.seq), args.max_frames or len(loop.seq)),
                                                              enabled=not args.quiet and sys.stderr.isatty()))
        status = "stopped"
        try:
            result = run_prepared(dataclasses.replace(loop, frames=frames), outputs.sinks if outputs else (),
                                  [outputs.can_log] if outputs else ())
            status = "done"
        finally:
            frames.close(status)
            if outputs:
                outputs.stop()
        summary = summary_of(result)
        if outputs:
            write_summary(outputs.paths["summary.json"], summary)
    except (FileNotFoundError, ValueError) as exc:
        raise CliError(str(exc)) from exc
    except OSError as exc:  # a full disk, a folder made read-only during the run
        raise CliError(f"cannot write the results in {args.out}: {exc.strerror or exc}", exit_code=1) from None
    except (KeyboardInterrupt, SystemExit):  # Ctrl-C, or SIGTERM/SIGHUP/SIGQUIT turned into SystemExit
        if args.out:
            print(f"gimbaltrack simulate: note: stopped before the end; the outputs so far are in {args.out} "
                  "(no summary.json)", file=sys.stderr)
        raise
    if args.json:
        print(json.dumps(summary))
        return 0
    ttc = summary["time_to_first_centre"]
    used = result.settings  # the tracker's resolved name, the view's field of view
    print(f"{summary['frames']} frames ({summary['frames_scored']} with ground truth, scored), "
          f"controller {used.controller}, tracker {used.tracker}, "
          f"view {args.size[0]}x{args.size[1]} at {used.hfov_deg:.1f} deg, "
          f"+{args.latency:g} ms latency (capture to bus, median {summary['median_capture_to_bus_ms']:.0f} ms)")
    print(f"centring error (fraction of the diagonal, at most {MAX_ERROR:g} a frame): "
          f"mean {summary['mean_center_error']:.4f}, RMS {summary['rms_center_error']:.4f}")
    print(f"out of view: {summary['out_of_view']:.1%} of scored frames")
    print(f"time to first centre: {'never' if ttc is None else f'{ttc:.2f} s'}, overshoot "
          f"{summary['overshoot']:.0%} of the initial offset (in the {OVERSHOOT_WINDOW_S:g} s after first centring)")
    if args.out:
        print(f"outputs: {args.out} (annotated.avi, telemetry.jsonl, can.log, plot.png, summary.json)")
    return 0
