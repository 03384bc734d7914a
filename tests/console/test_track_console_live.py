"""The console with a live source on a bus of its own: a UDP stream (ffmpeg, real time) tracked
against a ``gimbaltrack sim`` in another process over udp_multicast. Pause stops and releases
that gimbal; stop ends the run with status 0."""
from __future__ import annotations

import json
import subprocess
from pathlib import Path

from gimbal.client import SPEED_RELEASE
from tests.console.http_helpers import post, request
from tests.console.track_run import ConsoleRun
from tests.support import (
    ROOT,
    cli_command,
    free_udp_port,
    require_ffmpeg,
    subprocess_env,
    wait_until,
)
from tests.track.helpers import (
    DEMO,
    assert_stopped_at_end,
    decoded,
    speed_commands,
    start,
)

GROUP = "239.74.163.9"


def test_a_live_stream_and_a_gimbal_in_another_process(tmp_path: Path) -> None:
    ffmpeg = require_ffmpeg("a live UDP stream")
    env = subprocess_env(free_udp_port())
    sim = start(cli_command("sim", "-i", "udp_multicast", "-c", GROUP, "--status-interval", "1", "--json"), env)
    port = free_udp_port()
    url = f"udp://127.0.0.1:{port}"
    streamer = subprocess.Popen(
        [ffmpeg, "-loglevel", "error", "-re", "-stream_loop", "3", "-i", str(DEMO), "-t", "30",
         "-c:v", "mpeg2video", "-q:v", "4", "-f", "mpegts", f"{url}?pkt_size=1316"],
        cwd=ROOT, stdin=subprocess.DEVNULL)
    run = None
    try:
        assert wait_until(lambda: sim.stdout.readline() != "", 10), "the simulator did not start"
        run = ConsoleRun(tmp_path, "-i", "udp_multicast", "-c", GROUP, source=url, env=env)

        def state() -> dict:
            return json.loads(request(run.port, "GET", "/api/state")[2])

        assert wait_until(lambda: (state()["frame"] or 0) > 20 and state()["attitude_deg"] is not None, 30)
        assert state()["bus"]["silent"] is False
        assert post(run.port, "/api/pause")[0] == 200
        assert wait_until(lambda: state()["state"] == "paused", 10)
        paused_at = state()["frame"]
        assert wait_until(lambda: state()["frame"] > paused_at + 10, 10)  # the view follows the stream
        assert post(run.port, "/api/stop")[0] == 200
        code, _, stderr = run.finish()
    finally:
        if run is not None:
            run.kill()
        for process in (streamer, sim):
            process.kill()
            process.wait()
    assert code == 0, stderr
    summary = json.loads((run.out / "summary.json").read_text())
    assert summary["live"] is True and summary["status"] == "stopped from the console"
    records = decoded(run.out / "can.log")
    speeds = speed_commands(records)
    release = next(i for i, s in enumerate(speeds) if s.ctrl == SPEED_RELEASE)
    assert speeds[release].zero and speeds[release - 1].zero
    assert_stopped_at_end(records)
