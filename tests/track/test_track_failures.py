"""``gimbaltrack track`` when things go wrong: bad input, a bus that never answers or falls silent,
and SIGINT/SIGTERM; every time a one-line error, a non-zero exit, the outputs kept and the
gimbal told to stop."""
from __future__ import annotations

import errno
import json
import signal
import threading
import time
from pathlib import Path
from typing import Any

import cv2
import pytest

import gimbal.sim
import pipelines.cli.bus
import pipelines.cli.track_cmd
import pipelines.outputs.plot
import pipelines.loop.track_session
from gimbal.client import GimbalClient
from gimbal.errors import ReturnCodeError
from gimbal.sim import Faults
from pipelines.cli import main
from pipelines.loop.acquire import AcquiringSubject
from pipelines.outputs.telemetry import TelemetryWriter, read_telemetry
from tests import fake_onnx
from tests.support import ROOT, cli_command, free_udp_port, subprocess_env, wait_until
from tests.track.helpers import (
    DEMO, DEMO_ROI, assert_stopped_at_end, decoded, drifting, make_clip, roi_at, run_track, speed_commands,
    start, track_command,
)


GROUP = "239.74.163.9"


def _one_line_error(capsys: pytest.CaptureFixture[str], *words: str) -> str:
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert err.startswith("gimbaltrack track: error:") and "Traceback" not in err
    assert all(w in err for w in words), err
    return err


@pytest.mark.parametrize("args, words", [
    (["--roi", "1,2,x,4"], ["--roi"]),
    (["--roi", "inf,0,10,10"], ["--roi", "x,y,w,h"]),  # once an OverflowError traceback
    (["--roi", "10,10,0,5"], ["w and h"]),
    (["--tracker", "no-such-tracker"], ["no-such-tracker"]),
    (["--max-speed", "400"], ["--max-speed"]),
    (["--rate", "2"], ["--rate", "4 to 50"]),  # once a traceback from the keep-alive
    (["--rate", "inf"], ["--rate"]),
    (["--roi", "700,400,64,96"], ["--roi", "outside the 640x360 frame"]),  # once tracked the background
    (["--roi", "138,152,64,96", "-c", "can0"], ["-c/--channel", "give -i"]),  # once the simulator, silently
    (["--roi", "138,152,64,96", "--fps", "-3"], ["--fps"]),  # once a traceback
    (["--roi", "138,152,64,96", "--hfov", "0"], ["--hfov takes 0 < DEG < 180"]),
    (["--roi", "138,152,64,96", "--out", str(ROOT / "README.md")], ["is a file, not a folder"]),
])
def test_bad_options_are_one_line_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                         args: list[str], words: list[str]) -> None:
    assert run_track(DEMO, tmp_path / "out", *args) == 2
    _one_line_error(capsys, *words)


@pytest.mark.parametrize("backbone, head, wrong", [
    (b"junk!", fake_onnx.head_bytes(), "nanotrack_backbone_sim.onnx: not a readable ONNX network"),
    (fake_onnx.head_bytes(), fake_onnx.backbone_bytes(), "nanotrack_backbone_sim.onnx: not NanoTrack's backbone"),
    (fake_onnx.backbone_bytes(), fake_onnx.backbone_bytes(), "nanotrack_head_sim.onnx: not NanoTrack's neck/head"),
])
def test_wrong_model_files_are_named_in_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                 backbone: bytes, head: bytes, wrong: str) -> None:
    models = fake_onnx.write_nanotrack_files(tmp_path / "models", backbone, head)  # once a cv2.error traceback
    assert run_track(DEMO, tmp_path / "out", "--roi", DEMO_ROI, "--tracker", "nanotrack", "--model-dir", str(models)) == 2
    _one_line_error(capsys, wrong)
    assert not (tmp_path / "out").exists()  # checked before it is created, as the source is


def test_missing_model_files_create_no_out_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The tracker was once made after --out and its can.log: the folder was left behind."""
    (tmp_path / "models").mkdir()
    assert run_track(DEMO, tmp_path / "out", "--roi", DEMO_ROI, "--tracker", "nanotrack",
                     "--model-dir", str(tmp_path / "models")) == 2
    _one_line_error(capsys, "NanoTrack: no nanotrack_backbone*.onnx in")
    assert not (tmp_path / "out").exists()


def test_missing_and_garbage_sources(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert run_track(tmp_path / "nothing.mp4", tmp_path / "out") == 2
    _one_line_error(capsys, "nothing.mp4")
    garbage = tmp_path / "garbage.mp4"
    garbage.write_bytes(bytes(range(256)) * 64)
    assert run_track(garbage, tmp_path / "out") == 2
    _one_line_error(capsys, "garbage.mp4")


def test_a_gimbal_that_never_answers(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                     monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CAN_CONFIG", json.dumps({"port": free_udp_port()}))  # nobody else on it
    out = tmp_path / "out"
    assert run_track(DEMO, out, "--roi", DEMO_ROI, "-i", "udp_multicast", "-c", GROUP) == 1
    _one_line_error(capsys, "does not answer")
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "gimbal not answering" and summary["frames"] == 0
    names = [r.get("name") for r in decoded(out / "can.log")]
    assert "push_control" in names and "speed_control" not in names


def test_a_bus_falling_silent_mid_run(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                      monkeypatch: pytest.MonkeyPatch) -> None:
    """Issue #26 item 1: a gimbal silent from 1 s on once ended the run (exit 1, ~10 commands
    after the silence began). Now it is released after the bus timeout, the run tracks to the
    source's end and says how the link was (exit 3)."""
    real = gimbal.sim.start_in_process
    monkeypatch.setattr(pipelines.cli.bus, "start_in_process",
                        lambda config=None, faults=None: real(config, Faults(silent=(1.0, 60.0))))
    out = tmp_path / "out"
    assert run_track(DEMO, out, "--roi", DEMO_ROI, "--no-video", "--realtime") == 3  # outlasts 1 s
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert not any("Traceback" in line or "error:" in line for line in err)
    assert any("stopped and released" in line for line in err)
    assert "gimbal link: degraded (1 episode, released 1 time)" in captured.out
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "end of source" and summary["frames"] == 270
    assert summary["bus_health"]["state"] == "disengaged" and summary["bus_health"]["unreachable_s"] > 5
    assert len(read_telemetry(out / "telemetry.jsonl")) == summary["frames"]
    assert (out / "plot.png").stat().st_size > 0
    records = decoded(out / "can.log")
    assert_stopped_at_end(records)  # sent although nobody listens any more
    assert any(not c.zero for c in speed_commands(records))


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_a_can_log_that_cannot_be_written_ends_the_run_with_the_gimbal_stopped(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    sims = []
    real = gimbal.sim.start_in_process

    def keep(config=None, faults=None):  # type: ignore[no-untyped-def]
        bus, sim = real(config, faults)
        sims.append(sim)
        return bus, sim

    monkeypatch.setattr(pipelines.cli.bus, "start_in_process", keep)
    out = tmp_path / "out"
    out.mkdir()
    (out / "can.log").symlink_to("/dev/full")  # the disk is full from the first frame on
    assert run_track(DEMO, out, "--roi", DEMO_ROI, "--no-video") == 1
    _one_line_error(capsys, "cannot write the CAN log", "told to stop")
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "output failed" and summary["frames"] >= 1
    state = sims[0].state()
    assert state.commands["speed_control"] >= 3 and not state.speed_control  # taken, then released


def _wait_for(predicate, timeout: float, what: str) -> None:  # type: ignore[no-untyped-def]
    assert wait_until(predicate, timeout, step=0.05), f"timed out waiting for {what}"


@pytest.mark.parametrize("signums, code, status", [
    ([signal.SIGINT], 130, "interrupted (SIGINT)"),
    ([signal.SIGTERM], 143, "terminated (SIGTERM)"),
    ([signal.SIGHUP], 129, "terminated (SIGHUP)"),  # the terminal closed
    ([signal.SIGQUIT], 131, "terminated (SIGQUIT)"),  # Ctrl-\ (docs/track.md's exit codes)
    ([signal.SIGINT, signal.SIGINT], 130, "interrupted (SIGINT)"),  # an impatient second Ctrl-C
])
def test_signals_stop_the_gimbal_and_keep_the_outputs(tmp_path: Path, signums: list[int], code: int,
                                                      status: str) -> None:
    """track and a ``gimbaltrack sim`` in separate processes on udp_multicast (a private port)."""
    env = subprocess_env(free_udp_port())
    sim = start(cli_command("sim", "-i", "udp_multicast", "-c", GROUP, "--status-interval", "0.1", "--json"),
                env)
    out = tmp_path / "out"
    # Read the status lines as they come: a pipe left unread fills (~10 s at 10 lines/s) and stalls
    # the simulator, whose last line would then be an old one from mid-run.
    sim_lines: list[str] = []
    reader = threading.Thread(target=lambda: sim_lines.extend(sim.stdout), daemon=True)  # type: ignore[arg-type]
    reader.start()
    try:
        _wait_for(lambda: sim_lines, 30, "the simulator")
        track = start(track_command(DEMO, out, "--roi", DEMO_ROI, "--realtime", "-i", "udp_multicast",
                                    "-c", GROUP), env)
        telemetry = out / "telemetry.jsonl"
        _wait_for(lambda: telemetry.exists() and len(telemetry.read_text().splitlines()) > 40, 20,
                  "tracking")
        for signum in signums:
            track.send_signal(signum)
            time.sleep(0.002)
        stdout, stderr = track.communicate(timeout=15)
        assert track.returncode == code, stderr
        assert "Traceback" not in stderr
        time.sleep(0.5)  # the simulator decelerates (720 deg/s^2) and reports every 0.1 s
    finally:
        sim.send_signal(signal.SIGTERM)
        sim.wait(timeout=10)
        reader.join(timeout=10)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == status and status in stdout
    frames = summary["frames"]
    assert 40 < frames < 270 and len(read_telemetry(out / "telemetry.jsonl")) == frames
    assert (out / "plot.png").exists() and (out / "annotated.avi").stat().st_size > 0
    records = decoded(out / "can.log")
    assert any(not c.zero for c in speed_commands(records)), "the gimbal never moved"
    assert_stopped_at_end(records)
    final = json.loads(sim_lines[-1])
    assert final["speeds"] == [0.0, 0.0, 0.0] and not final["moving"] and not final["speed_control"]


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_telemetry_that_cannot_be_written_ends_with_a_summary_not_a_traceback(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "telemetry.jsonl").symlink_to("/dev/full")
    assert run_track(DEMO, out, "--roi", DEMO_ROI, "--no-video") == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.strip().splitlines()[-1].startswith("gimbaltrack track: error:")
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "output failed"
    assert_stopped_at_end(decoded(out / "can.log"))


def test_a_gimbal_refusing_the_start_up_commands_is_one_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    real = gimbal.sim.start_in_process
    monkeypatch.setattr(pipelines.cli.bus, "start_in_process",
                        lambda config=None, faults=None: real(config, Faults(nack=1.0)))
    out = tmp_path / "out"
    assert run_track(DEMO, out, "--roi", DEMO_ROI, "--no-video") == 1
    _one_line_error(capsys, "refused to start", "0x02")
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "gimbal refused to start"
    assert all(Path(path).exists() for path in summary["outputs"].values())  # no plot listed without frames


def test_a_recording_started_but_not_confirmed_is_still_stopped(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(self):  # type: ignore[no-untyped-def]
        raise ReturnCodeError("camera_status_query", 0x02)

    monkeypatch.setattr(GimbalClient, "camera_status", refuse)
    out = tmp_path / "out"
    assert run_track(DEMO, out, "--roi", DEMO_ROI, "--no-video", "--record", "--max-frames", "30") == 0
    recording = json.loads((out / "summary.json").read_text())["recording"]
    assert recording["started"] is True and recording["start_confirmed"] is False
    assert recording["stopped"] is True
    actions = [r["fields"]["action"] for r in decoded(out / "can.log") if r.get("name") == "camera_action"]
    assert actions == [3, 4]  # start, then stop at the end


@pytest.mark.parametrize("signum, code, status", [
    (signal.SIGINT, 130, "interrupted while starting (SIGINT)"),
    (signal.SIGTERM, 143, "terminated while starting (SIGTERM)"),
])
def test_a_signal_just_after_the_output_folder_appears_still_leaves_a_summary(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, signum: int, code: int, status: str) -> None:
    """A signal before the session existed once ended the run with no summary.json."""
    real = pipelines.cli.track_cmd.make_out_dir

    def make_then_signal(path: Path) -> None:
        real(path)
        signal.raise_signal(signum)

    monkeypatch.setattr(pipelines.cli.track_cmd, "make_out_dir", make_then_signal)
    out = tmp_path / "out"
    assert run_track(DEMO, out, "--roi", DEMO_ROI, "--no-video") == code
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == status and summary["frames"] == 0


@pytest.fixture
def plot_on_full_disk(monkeypatch: pytest.MonkeyPatch) -> None:
    """Writing the plot fails as on a full disk (the last output a run writes)."""
    def disk_full(*args: object, **kwargs: object) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(pipelines.outputs.plot, "write_timeseries_png", disk_full)


@pytest.mark.usefixtures("plot_on_full_disk")
def test_an_output_that_fails_at_the_end_is_one_line_with_the_summary_saying_so(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A full disk once failed the plot (or the final summary) with a traceback after the last frame."""
    out = tmp_path / "out"
    assert run_track(DEMO, out, "--roi", DEMO_ROI, "--no-video", "--max-frames", "20") == 1
    _one_line_error(capsys, "plot: No space left on device", "the gimbal was told to stop")
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "output failed" and summary["frames"] == 20
    assert "plot" not in summary["outputs"] and not (out / "plot.png").exists()
    assert_stopped_at_end(decoded(out / "can.log"))


def test_a_setup_error_is_not_hidden_by_a_signal_held_meanwhile(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    """The held SIGTERM once replaced the error: exit 143 and no word of what had failed."""
    def broken(self, *args: object, **kwargs: object) -> None:
        signal.raise_signal(signal.SIGTERM)
        raise ValueError("cannot load the tracker model: no such file")

    monkeypatch.setattr(pipelines.cli.track_cmd.TrackSession, "__init__", broken)
    assert run_track(DEMO, tmp_path / "out", "--roi", DEMO_ROI, "--no-video") == 2
    _one_line_error(capsys, "cannot load the tracker model")


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
@pytest.mark.usefixtures("plot_on_full_disk")
def test_the_failure_that_ended_the_run_stays_in_the_summary(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """On a full disk several outputs fail one after the other: the summary keeps the failure that
    ended the run, not the last one met while finalising the others."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "can.log").symlink_to("/dev/full")  # full from the first frame on; the plot fails at the end
    assert run_track(DEMO, out, "--roi", DEMO_ROI, "--no-video") == 1
    assert "cannot write the CAN log" in capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "output failed" and "cannot write the CAN log" in summary["error"]
    assert "plot" not in summary["outputs"]


# ``gimbaltrack track`` when the source fails or the code crashes part-way through a run: the
# session itself stops the gimbal (zero, then release) and the summary says how the run ended,
# with every frame so far in the telemetry.
FRAMES = 20


def _assert_stopped_by_the_session(out: Path, status: str, frames: int) -> dict[str, Any]:
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == status and summary["frames"] == frames
    assert len(read_telemetry(out / "telemetry.jsonl")) == frames
    sends = summary["speed_commands"]
    assert sends["stop_zero_sent"] == sends["stop_release_sent"] == 1
    assert_stopped_at_end(decoded(out / "can.log"))
    return summary


def test_a_source_failing_mid_run_stops_the_gimbal_and_exits_1(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    video = cv2.VideoCapture(str(make_clip(tmp_path / "clip.avi", FRAMES, drifting)))
    folder = tmp_path / "frames"
    folder.mkdir()
    for i in range(FRAMES):
        ok, image = video.read()
        assert ok
        if i == 12:  # one image of another size: the folder source fails there
            image = cv2.resize(image, (160, 120))
        cv2.imwrite(str(folder / f"{i:03d}.png"), image)
    out = tmp_path / "out"
    assert run_track(folder, out, "--roi", roi_at(drifting), "--no-video") == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("gimbaltrack track: error:")
    assert "012.png" in err and "outputs so far are in" in err
    summary = _assert_stopped_by_the_session(out, "source failed", 12)
    assert "one frame size" in summary["error"]


def test_a_crash_mid_run_stops_the_gimbal_and_keeps_the_outputs(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    real = AcquiringSubject.estimate
    calls: list[int] = []

    def crash_on_the_eighth(self: AcquiringSubject, *args: Any) -> Any:
        calls.append(1)
        if len(calls) == 8:
            raise RuntimeError("a bug")
        return real(self, *args)

    monkeypatch.setattr(AcquiringSubject, "estimate", crash_on_the_eighth)
    clip = make_clip(tmp_path / "clip.avi", FRAMES, drifting)
    out = tmp_path / "out"
    with pytest.raises(RuntimeError, match="a bug"):  # a bug shows its traceback
        run_track(clip, out, "--roi", roi_at(drifting))
    summary = _assert_stopped_by_the_session(out, "failed", 7)
    assert summary["error"] == "RuntimeError('a bug')"
    assert (out / "plot.png").exists()


def test_a_telemetry_line_that_cannot_be_written_is_not_counted(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The disk fills up at the eighth frame's telemetry line: the summary's ``frames`` (and its
    states) count the seven frames the telemetry holds, not the eighth, whose line is missing."""
    real = TelemetryWriter.write
    calls: list[int] = []

    def full_at_the_eighth(self: TelemetryWriter, record: Any) -> None:
        calls.append(1)
        if len(calls) == 8:
            raise OSError(errno.ENOSPC, "No space left on device")
        real(self, record)

    monkeypatch.setattr(TelemetryWriter, "write", full_at_the_eighth)
    out = tmp_path / "out"
    assert run_track(make_clip(tmp_path / "clip.avi", FRAMES, drifting), out,
                     "--roi", roi_at(drifting), "--no-video") == 1
    summary = _assert_stopped_by_the_session(out, "output failed", 7)
    assert sum(summary["states"].values()) == 7 and summary["angular_error_deg"]["frames"] <= 7


# An output that cannot even be opened (here the telemetry's name taken by a folder) is a one-line
# error and exit 2 before the gimbal is ever moved, not a traceback.
def test_an_output_that_cannot_be_opened_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    def position(i: int) -> tuple[int, int]:
        return 140 + i, 100

    clip = make_clip(tmp_path / "clip.avi", 5, position)
    out = tmp_path / "out"
    (out / "telemetry.jsonl").mkdir(parents=True)
    assert run_track(clip, out, "--roi", roi_at(position), "--no-video") == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("gimbaltrack track: error:")
    assert "telemetry.jsonl" in err and "Traceback" not in err
    assert speed_commands(decoded(out / "can.log")) == []


# The last rewrite of ``summary.json`` failing (a full disk) after a run that went well: a one-line
# error and exit 1, the gimbal stopped first, and the previous rewrite left in place.
def test_a_final_summary_that_cannot_be_written_is_one_line_and_exit_1(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    real = pipelines.loop.track_session.write_summary

    def full_at_the_end(path: Path, summary: dict[str, Any], sync: bool = True) -> None:
        if sync:  # the final rewrite; those during the run pass sync=False
            raise OSError(errno.ENOSPC, "No space left on device")
        real(path, summary, sync)

    monkeypatch.setattr(pipelines.loop.track_session, "write_summary", full_at_the_end)

    clip = make_clip(tmp_path / "clip.avi", 12, drifting)
    out = tmp_path / "out"
    assert run_track(clip, out, "--roi", roi_at(drifting), "--no-video") == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("gimbaltrack track: error:")
    assert "summary: No space left on device" in err and "the gimbal was told to stop" in err
    assert json.loads((out / "summary.json").read_text())["status"] == "running"  # the last rewrite that fitted
    assert_stopped_at_end(decoded(out / "can.log"))


# A ``face_detection_yunet*.onnx`` in ``--model-dir`` that is damaged, or another network under
# YuNet's name, is a one-line error naming the file, exit 2, before ``--out`` is created (it was a
# cv2.error traceback: at the start for a damaged file, at the first frame, mid-run, for another
# network).
@pytest.mark.parametrize("content", [b"not a network", fake_onnx.head_bytes(), fake_onnx.backbone_bytes()],
                         ids=["damaged", "nanotrack-head", "nanotrack-backbone"])
def test_a_bad_yunet_file_is_a_one_line_error(content: bytes, tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    models = tmp_path / "models"
    models.mkdir()
    model = models / "face_detection_yunet_2023mar.onnx"
    model.write_bytes(content)
    out = tmp_path / "out"
    assert run_track(make_clip(tmp_path / "clip.avi", 5, drifting), out, "--detect", "face",
                     "--model-dir", str(models), "--no-video") == 2
    err = capsys.readouterr().err
    assert err == (f"gimbaltrack track: error: YuNet face detector {model}: not a YuNet network "
                   "(damaged or another file?)\n")
    assert not out.exists()


def test_the_help_and_docs_name_the_same_exit_statuses(capsys: pytest.CaptureFixture[str]) -> None:
    """``track --help`` once left out that a gimbal silent at start is exit 1; docs/track.md says so."""
    with pytest.raises(SystemExit):
        main(["track", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    statuses = help_text.split("exit status:", 1)[1]
    assert "1 the gimbal did not answer at start" in statuses
    for code in (0, 1, 2, 3, 4, 129, 130, 131, 143):
        assert f" {code} " in f" {statuses}", code
    docs = " ".join((ROOT / "docs" / "track.md").read_text().split())
    assert "1 the gimbal does not answer at start" in docs
