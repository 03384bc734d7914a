"""The operator console's cost to the loop and its view's latency, A/B against the same run without it.

On the 1280x720 clip ``bench_pipeline.py`` makes (the shared vot15_ball1 frames looped, or the demo
clip upscaled when the shared data is absent), in interleaved rounds:

- A: ``gimbaltrack track CLIP --roi R --no-video`` (built-in simulated gimbal), file speed;
- B: the same with ``--console 127.0.0.1:0`` and one viewer attached for the whole run, reading
  ``/stream.mjpg`` at the page's defaults (15 fps, 960 px wide).

The loop's fps is the summary's (frames / elapsed). On a shared machine that figure moves with
the others' load from one run to the next, so the process's CPU time per frame while the loop
runs (user + system from /proc/PID/stat, over the telemetry's lines between its 10th and its
last-but-one sample; start-up and the end's plot are left out) is printed beside it: the
console's cost in CPU, which on an idle 2-core machine is what would take fps from the loop. The viewer's latency is, for each MJPEG part,
its ``X-Capture-Time`` (the frame's time on the machine's monotonic clock) to the moment the whole
part has been read by the viewer (``time.monotonic()`` in this process: the same clock). With
``--realtime`` the clip plays at its own 30 fps instead, as a camera would deliver it. Targets:
B's fps >= 90 % of A's; capture -> frame in the viewer p50 <= 100 ms. The load average at the
start and the end is printed with the figures: they are only comparable at a similar load.

    .venv/bin/python benchmarks/bench_console.py [--loops 3] [--rounds 3] [--realtime]
"""
from __future__ import annotations

import argparse
import http.client
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from bench_pipeline import make_clip  # noqa: E402
from machine import describe_machine  # noqa: E402


class Viewer(threading.Thread):
    """Reads the MJPEG stream, keeping (frame index, capture -> received seconds) per part."""

    def __init__(self, port: int) -> None:
        super().__init__(daemon=True)
        self.port = port
        self.parts: list[tuple[int, float]] = []

    def run(self) -> None:
        connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=30)
        try:
            connection.request("GET", "/stream.mjpg")
            response = connection.getresponse()
            while True:
                line = response.readline()
                if not line:
                    return
                if line.strip() != b"--frame":
                    continue
                headers = {}
                while (line := response.readline().strip()):
                    name, _, value = line.decode().partition(":")
                    headers[name.strip().lower()] = value.strip()
                response.read(int(headers["content-length"]))
                self.parts.append((int(headers["x-frame-index"]),
                                   time.monotonic() - float(headers["x-capture-time"])))
        except (OSError, http.client.HTTPException):
            return  # the run ended
        finally:
            connection.close()


class CpuSampler(threading.Thread):
    """Samples (telemetry lines, process CPU seconds) every 0.1 s while the run goes."""

    def __init__(self, pid: int, telemetry: Path) -> None:
        super().__init__(daemon=True)
        self.pid, self.telemetry = pid, telemetry
        self.samples: list[tuple[int, float]] = []
        self.ticks = os.sysconf("SC_CLK_TCK")

    def run(self) -> None:
        while True:
            try:
                fields = Path(f"/proc/{self.pid}/stat").read_text().rsplit(")", 1)[1].split()
                lines = self.telemetry.read_bytes().count(b"\n") if self.telemetry.exists() else 0
            except OSError:
                return
            if fields[0] == "Z":
                return
            self.samples.append((lines, (int(fields[11]) + int(fields[12])) / self.ticks))
            time.sleep(0.1)

    def ms_per_frame(self) -> float | None:
        running = [s for s in self.samples if s[0] >= 10]
        if len(running) < 3 or running[-2][0] <= running[0][0]:
            return None
        (f0, c0), (f1, c1) = running[0], running[-2]
        return (c1 - c0) * 1000.0 / (f1 - f0)


def track(clip: Path, out: Path, roi: str, console: bool, realtime: bool) -> tuple[float, float, list[float]]:
    """The loop's fps, its CPU ms per frame and, with the console, the viewer's latencies (s)."""
    (out / "telemetry.jsonl").unlink(missing_ok=True)
    command = [sys.executable, "-m", "pipelines.cli", "track", str(clip), "--out", str(out), "--quiet",
               "--json", "--roi", roi, "--no-video"] + (["--realtime"] if realtime else [])
    if console:
        command += ["--console", "127.0.0.1:0"]
    process = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    sampler = CpuSampler(process.pid, out / "telemetry.jsonl")
    sampler.start()
    viewer = None
    if console:
        for line in process.stderr:
            found = re.search(r"console at http://[^:]+:(\d+)/", line)
            if found:
                viewer = Viewer(int(found.group(1)))
                viewer.start()
                break
    stdout, stderr = process.communicate()
    if process.returncode != 0:
        sys.exit(f"bench_console: track exited {process.returncode}: {stderr.strip()}")
    if viewer is not None:
        viewer.join(timeout=10)
    sampler.join()
    summary = json.loads(stdout)
    cpu_ms = sampler.ms_per_frame()
    return summary["fps"], math.nan if cpu_ms is None else cpu_ms, [latency for _, latency in viewer.parts] if viewer else []


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--loops", type=int, default=3, help="passes over the 105 ball1 frames (default 3)")
    parser.add_argument("--rounds", type=int, default=3, help="interleaved A/B rounds (default 3)")
    parser.add_argument("--realtime", action="store_true", help="play the clip at its own 30 fps")
    args = parser.parse_args()
    if args.loops < 1 or args.rounds < 1:
        parser.error("--loops and --rounds must be at least 1")
    load_before = os.getloadavg()
    with tempfile.TemporaryDirectory(prefix="bench_console_") as tmp:
        folder = Path(tmp)
        clip, roi, origin = make_clip(folder, args.loops, "h264")
        fps: dict[bool, list[float]] = {False: [], True: []}
        cpu: dict[bool, list[float]] = {False: [], True: []}
        latencies: list[float] = []
        for round_ in range(1, args.rounds + 1):
            for console in (False, True):
                rate, cpu_ms, seen = track(clip, folder / f"out{int(console)}", roi, console, args.realtime)
                fps[console].append(rate)
                cpu[console].append(cpu_ms)
                latencies += seen
            print(f"round {round_}: without {fps[False][-1]:.1f} fps ({cpu[False][-1]:.1f} CPU ms/frame), "
                  f"with console + 1 viewer {fps[True][-1]:.1f} fps ({cpu[True][-1]:.1f} CPU ms/frame), "
                  f"fps ratio {fps[True][-1] / fps[False][-1]:.2f}, {len(seen)} parts viewed", flush=True)
        print(describe_machine())
        print("load average (1, 5, 15 min) at the start {:.1f} {:.1f} {:.1f}, at the end {:.1f} {:.1f} {:.1f}"
              .format(*load_before, *os.getloadavg()))
        print(f"clip: {origin}, 1280x720 h264, subject {roi}, {'--realtime' if args.realtime else 'file speed'}, "
              f"{args.rounds} rounds")
        ratios = np.array(fps[True]) / np.array(fps[False])
        ratio = float(np.median(fps[True]) / np.median(fps[False]))
        print(f"loop fps median: without {np.median(fps[False]):.1f}, with {np.median(fps[True]):.1f}; "
              f"ratio {ratio:.2f} (per round {ratios.min():.2f}-{ratios.max():.2f}); "
              f"target >= 0.90: {'met' if ratio >= 0.9 else 'MISSED'}")
        print(f"CPU per frame median: without {np.nanmedian(cpu[False]):.2f} ms, with {np.nanmedian(cpu[True]):.2f} ms "
              f"(x{np.nanmedian(cpu[True]) / np.nanmedian(cpu[False]):.2f})")
        if latencies:
            ms = np.array(latencies) * 1000.0
            p50, p95, p99 = np.percentile(ms, [50, 95, 99])
            print(f"capture -> frame in the viewer ({len(ms)} parts): p50 {p50:.1f} ms, p95 {p95:.1f} ms, "
                  f"p99 {p99:.1f} ms, max {ms.max():.1f} ms; target p50 <= 100 ms: "
                  f"{'met' if p50 <= 100 else 'MISSED'}")


if __name__ == "__main__":
    main()
