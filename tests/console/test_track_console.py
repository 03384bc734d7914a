"""``gimbaltrack track --console``: every control reaches the loop, is in the telemetry, and does
on the bus what it says (the CAN log); stop ends the run with status 0 and its outputs."""
from __future__ import annotations

import http.client
import json
import threading
import time
from pathlib import Path

from gimbal.client import SPEED_RELEASE
from gimbal.messages.camera import CameraActionCode
from pipelines.cli.track_cmd import EXIT_DEGRADED_LINK
from pipelines.console.server import ConsoleServer
from pipelines.outputs.telemetry import read_telemetry
from tests.console.http_helpers import MjpegReader, post, request
from tests.console.track_run import FRAMES, ConsoleRun, drifting_slowly, subject_box
from tests.support import wait_until
from tests.track.helpers import (
    assert_stopped_at_end,
    decoded,
    host_commands,
    make_clip,
    run_track,
    speed_commands,
)


def state(run: ConsoleRun) -> dict:
    return json.loads(request(run.port, "GET", "/api/state")[2])


def test_each_control_acts_on_the_run_and_is_in_the_telemetry(tmp_path: Path) -> None:
    run = ConsoleRun(tmp_path)
    try:
        assert wait_until(lambda: (state(run)["frame"] or 0) >= 10, 30)
        frame = state(run)["frame"]
        box = subject_box(frame + 3)
        assert post(run.port, "/api/select", {"box": box}) == (200, {"ok": True})
        assert wait_until(lambda: state(run)["state"] == "tracking" and state(run)["frame"] > frame + 5, 10)
        assert post(run.port, "/api/record", {"on": True})[0] == 200
        assert wait_until(lambda: state(run)["recording"]["on"], 10)
        assert post(run.port, "/api/settings", {"max_speed": 30, "kp": 6})[0] == 200
        assert wait_until(lambda: state(run)["settings"]["max_speed"] == 30, 10)
        assert post(run.port, "/api/pause")[0] == 200
        assert wait_until(lambda: state(run)["state"] == "paused" and state(run)["paused"], 10)
        paused_at = state(run)["frame"]
        assert wait_until(lambda: state(run)["frame"] > paused_at + 10, 10)  # frames go on, the gimbal holds
        assert post(run.port, "/api/resume")[0] == 200
        assert wait_until(lambda: state(run)["state"] == "tracking", 10)
        assert post(run.port, "/api/record", {"on": False})[0] == 200
        status = state(run)
        for key in ("fps", "latency_ms", "attitude_deg", "bus", "source", "rates_dps", "confidence"):
            assert status[key] is not None, key
        assert status["bus"]["silent"] is False and status["fps"] > 5
        assert post(run.port, "/api/stop")[0] == 200
        code, _, stderr = run.finish()
    finally:
        run.kill()
    assert code == 0, stderr
    summary = run.summary()
    assert summary["status"] == "stopped from the console"
    assert summary["settings"]["max_speed"] == 30 and summary["settings"]["kp"] == 6
    lines = read_telemetry(run.out / "telemetry.jsonl")
    actions = [(line["frame"], a) for line in lines for a in line.get("operator", [])]
    assert [a["action"] for _, a in actions] == ["select", "record", "settings", "pause", "resume", "record", "stop"]
    select_frame, select = actions[0]
    assert select["box"] == box
    tracked = next(line for line in lines if line["frame"] == select_frame)
    assert tracked["state"] == "tracking"
    assert all(abs(a - b) <= 4 for a, b in zip(tracked["box"], box))  # restarted on that box
    paused = [line for line in lines if line["state"] == "paused"]
    assert len(paused) > 10

    records = decoded(run.out / "can.log")
    sent = host_commands(records)
    names = [r["name"] for r in sent]
    actions_sent = [r["fields"]["action"] for r in sent if r["name"] == "camera_action"]
    assert actions_sent == [CameraActionCode.START_RECORDING, CameraActionCode.STOP_RECORDING]
    # the pause: zero speed, then release, then nothing moving until the resume
    speeds = speed_commands(records)
    release = next(i for i, s in enumerate(speeds) if s.ctrl == SPEED_RELEASE)
    assert speeds[release].zero and speeds[release - 1].zero and not speeds[release - 1].released
    resumed = next(i for i in range(release + 1, len(speeds)) if not speeds[i].released)
    assert all(s.zero for s in speeds[release:resumed])
    assert any(not s.zero for s in speeds[resumed:])
    assert all(abs(s.yaw) <= 30 and abs(s.pitch) <= 30 for s in speeds[resumed:])  # the new limit
    assert "camera_action" in names
    assert_stopped_at_end(records)


def test_recenter_pauses_and_sends_the_gimbal_home(tmp_path: Path) -> None:
    run = ConsoleRun(tmp_path)
    try:
        assert wait_until(lambda: (state(run)["frame"] or 0) >= 5, 30)
        assert post(run.port, "/api/recenter")[0] == 200
        assert wait_until(lambda: state(run)["paused"], 10)
        assert post(run.port, "/api/stop")[0] == 200
        code, _, stderr = run.finish()
    finally:
        run.kill()
    assert code == 0, stderr
    lines = read_telemetry(run.out / "telemetry.jsonl")
    assert [a["action"] for line in lines for a in line.get("operator", [])] == ["recenter", "stop"]
    sent = host_commands(decoded(run.out / "can.log"))
    names = [r["name"] for r in sent]
    recenter = names.index("recenter_selfie")
    release = max(i for i, r in enumerate(sent[:recenter])
                  if r["name"] == "speed_control" and r["fields"]["ctrl_byte"] == SPEED_RELEASE)
    assert release < recenter


def test_closing_every_view_changes_nothing_and_a_bad_request_changes_nothing(tmp_path: Path) -> None:
    run = ConsoleRun(tmp_path)
    try:
        assert wait_until(lambda: (state(run)["frame"] or 0) >= 5, 30)
        reader = MjpegReader(run.port)
        reader.part()
        reader.close()
        assert request(run.port, "POST", "/api/select", '{"box": [9999, 0, 10, 10]}')[0] == 422
        frame = state(run)["frame"]
        assert wait_until(lambda: state(run)["frame"] > frame + 10, 10)
        assert post(run.port, "/api/stop")[0] == 200
        code, _, stderr = run.finish()
    finally:
        run.kill()
    assert code == 0, stderr
    lines = read_telemetry(run.out / "telemetry.jsonl")
    assert [a["action"] for line in lines for a in line.get("operator", [])] == ["stop"]


def test_a_console_on_another_address_prints_a_token_url(tmp_path: Path) -> None:
    run = ConsoleRun(tmp_path, console="0.0.0.0:0")
    try:
        assert "?token=" in run.url
        assert request(run.port, "GET", "/api/state")[0] == 401
        token = run.url.split("?token=")[1]
        assert post(run.port, "/api/stop", {}, headers={"Authorization": f"Bearer {token}"})[0] == 200
        code, _, stderr = run.finish()
    finally:
        run.kill()
    assert code == 0, stderr


def test_a_console_that_dies_stops_and_releases_the_gimbal(tmp_path: Path, monkeypatch, capsys) -> None:
    """The server's event loop is killed mid-run (its main task cancelled): the run ends like on
    any other output's failure, status 1, outputs kept, the gimbal stopped and released."""
    servers: list[ConsoleServer] = []
    original = ConsoleServer.start

    def start(self: ConsoleServer) -> str:
        servers.append(self)
        return original(self)

    monkeypatch.setattr(ConsoleServer, "start", start)

    def kill_the_server() -> None:
        assert wait_until(lambda: servers and servers[0].sink.latest() is not None
                          and servers[0].sink.latest().seq > 10, 30)
        servers[0]._loop.call_soon_threadsafe(servers[0]._main_task.cancel)

    killer = threading.Thread(target=kill_the_server, daemon=True)
    killer.start()
    clip = make_clip(tmp_path / "clip.avi", FRAMES, drifting_slowly)
    out = tmp_path / "out"
    code = run_track(clip, out, "--realtime", "--roi", ",".join(map(str, subject_box(0))), "--console", "0")
    killer.join()
    assert code == 1
    assert "the console stopped" in capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "output failed" and "console" in summary["error"]
    assert_stopped_at_end(decoded(out / "can.log"))
    assert len(read_telemetry(out / "telemetry.jsonl")) == summary["frames"] > 10


def test_a_file_at_file_speed_runs_to_its_end_with_the_view_following(tmp_path: Path) -> None:
    """No --realtime: the file is read as fast as the loop goes, the viewer is shown recent frames
    all the way (not a queue behind the loop), and the run ends by itself with status 0."""
    clip = make_clip(tmp_path / "clip.avi", FRAMES, drifting_slowly)
    run = ConsoleRun(tmp_path, source=str(clip))
    seen: list[tuple[int, float]] = []  # (frame index, capture -> received s)
    reader = MjpegReader(run.port, "?fps=30&width=320")
    try:
        while True:
            try:
                headers, data = reader.part()
            except (EOFError, OSError, http.client.HTTPException):
                break
            seen.append((int(headers["x-frame-index"]), time.monotonic() - float(headers["x-capture-time"])))
        code, _, stderr = run.finish()
    finally:
        reader.close()
        run.kill()
    assert code == 0, stderr
    summary = run.summary()
    assert summary["status"] == "end of source" and summary["frames"] == FRAMES
    indexes = [index for index, _ in seen]
    assert len(indexes) >= 10 and indexes == sorted(set(indexes)), indexes
    assert indexes[-1] >= FRAMES * 0.8, indexes  # it followed the file to (near) its end
    lags = sorted(lag for _, lag in seen)
    assert lags[len(lags) // 2] < 1.0, lags  # each shown when it was new, not from a backlog


def test_the_status_shows_refusals_timeouts_and_a_silent_gimbal(tmp_path: Path) -> None:
    """The built-in simulator refuses some commands, then falls silent: the status counts the
    NACKs, then the reply timeouts, and says the gimbal is silent. A stop then ends the run as
    stopped, with the degraded link's exit status like any run that lost its gimbal."""
    run = ConsoleRun(tmp_path, "--sim-faults", "nack=0.3,silent=4:60,seed=3")
    try:
        assert wait_until(lambda: state(run)["bus"]["nacks"] > 0, 20), state(run)["bus"]
        assert state(run)["bus"]["silent"] is False and state(run)["bus"]["timeouts"] == 0
        assert wait_until(lambda: state(run)["bus"]["silent"] and state(run)["bus"]["timeouts"] > 0, 20), \
            state(run)["bus"]
        assert post(run.port, "/api/stop")[0] == 200
        code, _, stderr = run.finish()
    finally:
        run.kill()
    assert code == EXIT_DEGRADED_LINK, stderr
    assert run.summary()["status"] == "stopped from the console"
