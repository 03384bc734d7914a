"""``gimbaltrack track A B ...``: each input against its own simulated gimbal, into OUT/<name>/,
reports in input order; a real bus refused; a failing input named; Ctrl-C stops every run cleanly."""
from __future__ import annotations

import json
import signal
import subprocess
from pathlib import Path

import pytest

from tests.support import cli_command, signalled, wait_until
from tests.track.helpers import assert_stopped_at_end, decoded, drifting, make_clip, roi_at


def track(*argv: str) -> subprocess.CompletedProcess:
    return subprocess.run(cli_command("track", *argv), capture_output=True, text=True, timeout=240)


@pytest.fixture(scope="module")
def clips(tmp_path_factory) -> list[Path]:
    root = tmp_path_factory.mktemp("clips")
    return [make_clip(root / f"{name}.avi", 40, drifting) for name in ("north", "south")]


def summary(folder: Path) -> dict:
    return json.loads((folder / "summary.json").read_text())


@pytest.mark.parametrize("jobs", [[], ["--jobs", "2"]])
def test_each_input_has_its_own_folder_gimbal_and_report_in_order(clips, tmp_path, jobs):
    out = tmp_path / "out"
    captured = track(str(clips[1]), str(clips[0]), "--roi", roi_at(drifting), "--no-video", "--out", str(out), *jobs)
    assert captured.returncode == 0, captured.stderr
    for clip in clips:
        done = summary(out / clip.stem)
        assert done["source"] == str(clip) and done["frames"] == 40 and done["status"] == "end of source"
        assert_stopped_at_end(decoded(out / clip.stem / "can.log"))
    reports = [line for line in captured.stdout.splitlines() if line.startswith("outputs: ")]
    assert reports == [f"outputs: {out / 'south'}", f"outputs: {out / 'north'}"]
    assert "Traceback" not in captured.stderr


def test_a_real_bus_is_refused_with_several_inputs(clips, tmp_path):
    captured = track(str(clips[0]), str(clips[1]), "-i", "virtual", "--out", str(tmp_path / "out"))
    assert captured.returncode == 2 and captured.stdout == ""
    assert captured.stderr == ("gimbaltrack track: error: 2 inputs need the simulated gimbal, each its own (one "
                               "gimbal cannot follow two subjects): give one SOURCE with -i/--interface\n")
    assert not (tmp_path / "out").exists()


def test_two_inputs_of_one_name_are_refused(clips, tmp_path):
    other = tmp_path / "elsewhere"
    other.mkdir()
    twin = other / clips[0].name
    twin.write_bytes(clips[0].read_bytes())
    captured = track(str(clips[0]), str(twin), "--out", str(tmp_path / "out"), "--jobs", "2")
    assert captured.returncode == 2 and captured.stderr.splitlines() == [
        f"gimbaltrack track: error: inputs {clips[0]} and {twin} would both write to {tmp_path / 'out' / 'north'}: "
        "rename one, or run them apart"]


@pytest.mark.parametrize("jobs", [[], ["--jobs", "2"]])
def test_a_failing_input_is_named_and_the_others_run(clips, tmp_path, jobs):
    broken = tmp_path / "broken.avi"
    broken.write_text("not a video")
    out = tmp_path / "out"
    captured = track(str(broken), str(clips[0]), "--roi", roi_at(drifting), "--no-video", "--out", str(out), *jobs)
    assert captured.returncode == 2
    errors = [line for line in captured.stderr.splitlines() if "error" in line]
    assert len(errors) == 1 and errors[0].startswith(f"gimbaltrack track: error: {broken}: ")
    assert summary(out / "north")["frames"] == 40 and "Traceback" not in captured.stderr


def test_ctrl_c_stops_every_run_and_keeps_their_outputs(tmp_path):
    clips = [make_clip(tmp_path / f"{name}.avi", 900, lambda i: (140 + i % 60, 100)) for name in ("east", "west")]
    out = tmp_path / "out"
    command = cli_command("track", *map(str, clips), "--roi", roi_at(drifting), "--no-video", "--realtime",
                          "--out", str(out), "--jobs", "2")
    telemetry = [out / clip.stem / "telemetry.jsonl" for clip in clips]

    def both_running(process: subprocess.Popen) -> bool:
        return wait_until(lambda: all(t.is_file() and t.stat().st_size > 2000 for t in telemetry), 120, 0.2)

    status, stdout, stderr = signalled(command, both_running, signum=signal.SIGINT,
                                       preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    assert status == 130 and "Traceback" not in stderr, stderr
    assert stderr.splitlines()[-1] == "gimbaltrack track: interrupted"
    for clip in clips:
        done = summary(out / clip.stem)
        assert done["status"] == "terminated (SIGTERM)" and 0 < done["frames"] < 900
        assert_stopped_at_end(decoded(out / clip.stem / "can.log"))
    assert [line for line in stdout.splitlines() if line.startswith("outputs: ")] == [
        f"outputs: {out / 'east'}", f"outputs: {out / 'west'}"]
