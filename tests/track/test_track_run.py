"""``gimbaltrack track`` end to end against the built-in simulator: the recorded command stream
(rate, range, direction, final stop, camera recording), the outputs, and loss of the subject."""
from __future__ import annotations

import json
import subprocess
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from gimbal.messages.camera import CameraActionCode
from pipelines.cli import track_cmd
from pipelines.cli.app import build_parser
from pipelines.control.controller import ControlConfig
from pipelines.control.gimbal_link import Signs
from pipelines.outputs.telemetry import read_telemetry
from pipelines.loop.track_session import TrackOptions
from tests.support import require_ffmpeg
from tests.track.helpers import (
    DEMO, DEMO_ROI, SIZE, assert_stopped_at_end, decoded, host_commands, in_speed_range, make_clip, roi_at,
    run_track, speed_commands,
)


SUMMARY_KEYS = {"status", "error", "source", "live", "bus", "tracker", "controller", "frames", "elapsed_s",
                "fps", "frames_dropped", "frames_expected", "states", "first_acquired_s", "angular_error_deg", "latency_ms",
                "speed_commands", "recording", "outputs"}


@pytest.fixture(scope="module")
def demo_run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    out = tmp_path_factory.mktemp("demo")
    code = run_track(DEMO, out, "--roi", DEMO_ROI, "--record")
    return {"code": code, "out": out, "records": decoded(out / "can.log"),
            "summary": json.loads((out / "summary.json").read_text())}


def test_demo_run_succeeds_and_stops_the_gimbal(demo_run: dict[str, Any]) -> None:
    assert demo_run["code"] == 0
    assert demo_run["summary"]["frames"] == demo_run["summary"]["frames_expected"] == 270
    assert demo_run["summary"]["status"] == "end of source"
    assert_stopped_at_end(demo_run["records"])
    sends = demo_run["summary"]["speed_commands"]  # the final zero and release counted too
    assert sends["stop_zero_sent"] == sends["stop_release_sent"] == 1
    assert sends["sent"] + 2 == len(speed_commands(demo_run["records"]))


def test_speed_commands_keep_the_configured_rate_within_range(demo_run: dict[str, Any]) -> None:
    """The keep-alive sends at least ``--rate`` (25 Hz) and, sending a new setpoint at once when
    half a period has passed, at most twice that; never a gap near the gimbal's 0.5 s expiry."""
    speeds = speed_commands(demo_run["records"])
    streamed = speeds[:-2]  # the last two are the stop
    times = np.array([c.t for c in streamed])
    rate = (len(times) - 1) / (times[-1] - times[0])
    assert 25 * 0.85 <= rate <= 2 * 25 * 1.05
    assert np.diff(times).max() < 0.25
    assert all(in_speed_range(c) for c in speeds)
    assert max(max(abs(c.yaw), abs(c.pitch)) for c in speeds) <= ControlConfig().max_speed_dps
    assert all(c.roll == 0 and c.ctrl == 0x88 for c in streamed)
    assert not any(r.get("out_of_range") for r in host_commands(demo_run["records"]))


def test_record_start_and_stop_are_sent_and_confirmed(demo_run: dict[str, Any]) -> None:
    actions = [r["fields"]["action"] for r in host_commands(demo_run["records"]) if r["name"] == "camera_action"]
    assert actions == [CameraActionCode.START_RECORDING, CameraActionCode.STOP_RECORDING]
    recording = demo_run["summary"]["recording"]
    assert recording["start_confirmed"] is True and recording["stop_confirmed"] is True


def test_outputs_are_complete_and_readable(demo_run: dict[str, Any]) -> None:
    out, summary = demo_run["out"], demo_run["summary"]
    assert SUMMARY_KEYS <= summary.keys()
    assert summary["frames"] == 270 and summary["states"]["tracking"] > 200
    telemetry = read_telemetry(out / "telemetry.jsonl")
    assert len(telemetry) == summary["frames"]
    assert [r["frame"] for r in telemetry] == list(range(270))
    assert all(len(r["rate_dps"]) == 2 and "error_deg" in r for r in telemetry)
    video = cv2.VideoCapture(str(out / "annotated.avi"))
    frames = 0
    while video.read()[0]:
        frames += 1
    assert frames == summary["frames"]
    plot = cv2.imread(str(out / "plot.png"))
    assert plot is not None and plot.shape[0] > 100 and plot.std() > 0
    latency, sends = summary["latency_ms"], summary["speed_commands"]
    # frames come faster than the keep-alive sends, so nearly every send but the final stop carries a
    # new setpoint (a stalled loop resends one), each measured once; how many there are depends on
    # how fast the run went
    fresh = sends["sent"] - sends["zero_sent"]
    assert 0.8 * fresh <= latency["count"] <= fresh and latency["count"] >= 10
    assert 0 < latency["p50"] <= latency["p99"]


def test_summary_angular_error_is_that_of_the_telemetry(demo_run: dict[str, Any]) -> None:
    telemetry = read_telemetry(demo_run["out"] / "telemetry.jsonl")
    errors = [float(np.hypot(*r["error_deg"])) for r in telemetry if r["error_deg"] is not None]
    assert demo_run["summary"]["angular_error_deg"] == pytest.approx(
        {"mean": sum(errors) / len(errors), "max": max(errors), "frames": len(errors)}, rel=1e-12)
    # no subject behind the command (idle, ramping down), no error
    assert all((r["error_deg"] is None) == (r["mode"] in ("idle", "ramp")) for r in telemetry)


# Image axes: x grows to the right, y downwards. Controller: yaw positive to the right, pitch
# positive upwards (pipelines.control.camera), so a subject below centre needs a negative pitch rate.
@pytest.mark.parametrize("corner, signs, rate", [
    ((230, 170), (1, -1), "25"),   # right of and below the centre
    ((40, 20), (-1, 1), "10"),     # left of and above it, slower keep-alive
])
def test_commands_point_towards_the_subject(tmp_path: Path, corner: tuple[int, int],
                                            signs: tuple[int, int], rate: str) -> None:
    def position(i: int) -> tuple[int, int]:
        return corner[0] + i % 3, corner[1]  # a slight jitter, well off centre

    clip = make_clip(tmp_path / "clip.avi", 45, position)
    assert run_track(clip, tmp_path / "out", "--roi", roi_at(position), "--no-video", "--rate", rate,
                     "--realtime") == 0
    records = decoded(tmp_path / "out" / "can.log")
    moving = [c for c in speed_commands(records) if not c.zero]
    assert len(moving) > 10
    assert all(np.sign(c.yaw) == signs[0] and np.sign(c.pitch) == signs[1] for c in moving)
    times = np.array([c.t for c in speed_commands(records)[:-2]])
    assert float(rate) * 0.85 <= (len(times) - 1) / (times[-1] - times[0]) <= 2 * float(rate) * 1.05
    assert_stopped_at_end(records)
    assert not (tmp_path / "out" / "annotated.avi").exists()


def test_inverted_axes_flip_the_rates_on_the_bus(tmp_path: Path) -> None:
    """--invert-yaw/--invert-pitch for gimbals whose axes turn the other way (FIELD_NOTES)."""
    def position(i: int) -> tuple[int, int]:
        return 230 + i % 3, 170  # right of and below the centre: normally yaw +, pitch -

    clip = make_clip(tmp_path / "clip.avi", 30, position)
    assert run_track(clip, tmp_path / "out", "--roi", roi_at(position), "--no-video", "--realtime",
                     "--invert-yaw", "--invert-pitch") == 0  # real time: a second of commands, not 0.1 s
    moving = [c for c in speed_commands(decoded(tmp_path / "out" / "can.log")) if not c.zero]
    assert len(moving) > 5
    assert all(c.yaw < 0 and c.pitch > 0 for c in moving)


def test_rates_ramp_to_zero_when_the_subject_leaves(tmp_path: Path) -> None:
    width = SIZE[0]

    def position(i: int) -> tuple[int, int] | None:
        x = 140 + 6 * i
        return (x, 100) if x < width else None

    gone = next(i for i in range(100) if position(i) is None)  # frame 30
    clip = make_clip(tmp_path / "leaves.avi", 60, position)  # 2 s, gone after 1 s
    assert run_track(clip, tmp_path / "out", "--roi", roi_at(position), "--no-video", "--realtime") == 0
    telemetry = read_telemetry(tmp_path / "out" / "telemetry.jsonl")
    lost_at = next(r for r in telemetry[1:] if r["state"] != "tracking")
    assert lost_at["frame"] <= gone + 10, "the tracker did not notice the subject leave"
    assert max(abs(v) for r in telemetry[: lost_at["frame"]] for v in r["rate_dps"]) > 50
    deadline = lost_at["t_run"] + ControlConfig().stop_within_s + 0.02  # a frame's slack
    after = [r for r in telemetry if r["t_run"] >= deadline]
    assert len(after) > 10 and all(r["rate_dps"] == [0.0, 0.0] for r in after)
    assert all(r["error_deg"] is None for r in after)  # no subject: no error, not a zero one
    assert all(r["mode"] in ("hold", "ramp", "idle") for r in telemetry if r["t_run"] > lost_at["t_run"])
    # the streamed commands end at rest too
    speeds = speed_commands(decoded(tmp_path / "out" / "can.log"))
    assert all(c.zero for c in speeds[-5:])


@pytest.mark.parametrize("width, expected", [("160", (160, 120)), ("0", SIZE)])
def test_annotated_video_is_shrunk_to_the_chosen_width(tmp_path: Path, width: str,
                                                       expected: tuple[int, int]) -> None:
    def position(i: int) -> tuple[int, int]:
        return 100 + i, 80

    clip = make_clip(tmp_path / "clip.avi", 10, position)
    assert run_track(clip, tmp_path / "out", "--roi", roi_at(position), "--video-width", width) == 0
    ok, frame = cv2.VideoCapture(str(tmp_path / "out" / "annotated.avi")).read()
    assert ok and frame.shape[1::-1] == expected


def test_demo_video_keeps_its_size_under_the_default_width(demo_run: dict[str, Any]) -> None:
    ok, frame = cv2.VideoCapture(str(demo_run["out"] / "annotated.avi")).read()
    assert ok and frame.shape[1::-1] == (640, 360)


def test_a_subject_never_acquired_is_said_and_recording_never_started(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    clip = make_clip(tmp_path / "empty.avi", 20, lambda i: None)  # background only
    assert run_track(clip, tmp_path / "out", "--detect", "motion", "--record", "--no-video") == 0
    assert "subject never acquired" in capsys.readouterr().out
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["first_acquired_s"] is None and summary["states"] == {"acquiring": 20}
    assert summary["recording"] == {"requested": True, "started": False, "error": "the subject was never acquired"}
    assert not [r for r in host_commands(decoded(tmp_path / "out" / "can.log")) if r["name"] == "camera_action"]


def test_a_file_cut_short_ends_with_a_warning(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Its index in front (faststart), the frames cut off: it decodes to the cut, then stops."""
    ffmpeg = require_ffmpeg("a clip cut short")
    whole = tmp_path / "whole.mp4"
    subprocess.run([ffmpeg, "-loglevel", "error", "-i", str(DEMO), "-c", "copy", "-movflags", "faststart",
                    str(whole)], check=True)
    cut = tmp_path / "cut.mp4"
    cut.write_bytes(whole.read_bytes()[: whole.stat().st_size // 2])
    assert run_track(cut, tmp_path / "out", "--roi", DEMO_ROI, "--no-video") == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["frames_expected"] == 270 and 0 < summary["frames"] < 0.95 * 270
    assert f"ended after {summary['frames']} of the 270 frames" in capsys.readouterr().err


def test_a_run_into_an_earlier_runs_folder_leaves_none_of_its_outputs(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert run_track(DEMO, out, "--roi", DEMO_ROI, "--max-frames", "5") == 0
    assert (out / "annotated.avi").exists() and (out / "plot.png").exists()
    assert run_track(DEMO, out, "--roi", DEMO_ROI, "--max-frames", "5", "--no-video") == 0
    assert not (out / "annotated.avi").exists()  # not a stale video beside the new run's outputs
    assert len(read_telemetry(out / "telemetry.jsonl")) == 5


def test_a_roi_over_the_frame_edge_is_tracked_as_given(tmp_path: Path,
                                                       capsys: pytest.CaptureFixture[str]) -> None:
    """Such a box was once cut to the frame, so the tracker followed a patch offset from the subject."""
    out = tmp_path / "out"
    assert run_track(DEMO, out, "--roi=-20,152,64,96", "--max-frames", "3", "--no-video") == 0
    assert "note" not in capsys.readouterr().err
    assert read_telemetry(out / "telemetry.jsonl")[0]["box"] == [-20, 152, 64, 96]


def test_speed_and_attitude_signs_are_inverted_separately() -> None:
    """--invert-yaw once flipped the attitude read too: on a gimbal that turns the other way but
    reports its angles the usual way (one RS 5), the filter saw the subject move the wrong way."""
    args = build_parser().parse_args(["track", "clip.mp4", "--invert-yaw", "--invert-pitch-attitude"])
    options = track_cmd._options(args)
    assert (options.yaw_sign, options.pitch_sign) == (-1, 1)
    assert options.signs == Signs(yaw_speed=-1, pitch_speed=1, yaw_attitude=1, pitch_attitude=-1)


# ``gimbaltrack track`` options at their limits (each side of a bound is one line and exit 2), and
# the subject's defaults: ``--detect motion`` following the largest mover unless a ``--roi`` is given.
@pytest.mark.parametrize("args, words", [
    (["--rate", "51"], "--rate takes 4 to 50 Hz"),
    (["--max-speed", "0"], "--max-speed takes 0 < DEG_S"),
    (["--max-frames", "0"], "--max-frames must be at least 1"),
    (["--video-width", "1"], "--video-width takes 0"),
])
def test_values_just_past_a_bound_are_one_line_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                      args: list[str], words: str) -> None:
    assert run_track(DEMO, tmp_path / "out", "--roi", DEMO_ROI, *args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("gimbaltrack track: error:") and words in err
    assert not (tmp_path / "out").exists()


def _options(*args: str) -> TrackOptions:
    return track_cmd._options(build_parser().parse_args(["track", "clip.mp4", *args]))


def test_the_subject_defaults_to_the_largest_mover() -> None:
    assert (_options().detect, _options().pick) == ("motion", "largest")
    assert (_options("--detect", "face").detect, _options("--detect", "face").pick) == ("face", "central")
    assert (_options("--roi", "1,2,3,4").detect, _options("--roi", "1,2,3,4").roi) == (None, (1, 2, 3, 4))
    assert _options("--detect", "motion", "--pick", "central").pick == "central"
