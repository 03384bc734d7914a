"""``gimbaltrack simulate``: what the summary reports, bad input caught before the run, SIGTERM."""
from __future__ import annotations

import json
import math
import shutil
import subprocess
import time
from pathlib import Path

import pytest

import pipelines.cli.app
from pipelines.cli import main
from pipelines.control.camera import DEFAULT_HFOV_DEG
from tests import fake_onnx
from tests.support import ROOT, cli_command, signalled, subprocess_env, wait_until

@pytest.fixture(autouse=True)
def only_simulate(monkeypatch: pytest.MonkeyPatch) -> None:
    """The real dispatcher, with only this subcommand (others' modules are not under test here)."""
    monkeypatch.setattr(pipelines.cli.app, "SUBCOMMAND_MODULES", ["pipelines.cli.simulate_cmd"])


def simulate(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(["simulate", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_summary_reports_the_tracker_and_field_of_view_used(sequence: Path, tmp_path: Path,
                                                            capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    code, stdout, _ = simulate([str(sequence), "--size", "480x270", "--fps", "60", "--json", "--out", str(out)],
                               capsys)
    assert code == 0
    summary = json.loads(stdout)
    # crop-equivalent: the 640 px source's focal length (24 mm full frame) seen by a 480 px view
    source_focal = 320 / math.tan(math.radians(DEFAULT_HFOV_DEG) / 2)
    assert summary["tracker"] == "nanovit"  # the default, resolved
    assert summary["fov_deg"] == pytest.approx(math.degrees(2 * math.atan(240 / source_focal)))
    assert json.loads((out / "summary.json").read_text()) == summary
    code, stdout, _ = simulate([str(sequence), "--fps", "60", "--fov", "50", "--tracker", "oracle"], capsys)
    assert code == 0 and "tracker oracle, view 640x360 at 50.0 deg" in stdout


def test_frames_without_truth_are_counted_and_left_out(sequence: Path, tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    gapped, out = tmp_path / "gapped", tmp_path / "out"
    shutil.copytree(sequence, gapped)
    truth = gapped / "groundtruth_rect.txt"
    rows = truth.read_text().splitlines()
    rows[4:8] = ["NaN,NaN,NaN,NaN", "NaN,NaN,NaN,NaN", "0,0,0,0", "0,0,0,0"]
    truth.write_text("\n".join(rows) + "\n")
    code, stdout, _ = simulate([str(gapped), "--size", "480x270", "--fps", "60", "--tracker", "oracle",
                                "--out", str(out)], capsys)
    assert code == 0 and stdout.startswith("12 frames (8 with ground truth, scored), controller pid")
    assert "out of view: 0.0% of scored frames" in stdout
    summary = json.loads((out / "summary.json").read_text())
    assert summary["frames"] == 12 and summary["frames_scored"] == 8 and (out / "plot.png").stat().st_size > 0


def test_model_dir_reaches_the_tracker(sequence: Path, shared_data: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    code, stdout, _ = simulate([str(sequence), "--fps", "60", "--json", "--tracker", "nanotrack", "--model-dir",
                                str(shared_data / "models")], capsys)
    assert code == 0 and json.loads(stdout)["tracker"] == "nanotrack"


@pytest.mark.parametrize("argv, message", [
    (["--out", "{file}"], "--out {file} is a file, not a folder"),
    (["--fov", "0"], "--fov takes 0 < DEG < 180, not 0"),
    (["--tracker", "nanotrack", "--model-dir", "{empty}"], "NanoTrack: no nanotrack_backbone*.onnx in {empty}"),
    (["--fov", "180"], "--fov takes 0 < DEG < 180, not 180"),
    (["--latency", "inf"], "--latency takes 0 to 2000 ms and --fps above 0 up to 1000"),  # once a traceback
    (["--size", "100000x100000"], "--size takes at most 8192 pixels a side, not 100000x100000"),  # once cv2.error
])
def test_bad_options_fail_at_once_in_one_line(argv: list[str], message: str, sequence: Path, tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    file, empty = tmp_path / "results", tmp_path / "models"
    file.write_text("")
    empty.mkdir()
    started = time.monotonic()
    # --fps 1: the run itself would take 12 s
    code, stdout, err = simulate([str(sequence), "--fps", "1", *(a.format(file=file, empty=empty) for a in argv)],
                                 capsys)
    assert time.monotonic() - started < 6
    assert code == 2 and stdout == ""
    assert err.startswith(f"gimbaltrack simulate: error: {message.format(file=file, empty=empty)}")
    assert err.count("\n") == 1


def test_results_that_cannot_be_written_are_one_line_and_exit_1(sequence: Path, tmp_path: Path,
                                                                 monkeypatch: pytest.MonkeyPatch,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    import pipelines.cli.simulate_cmd

    def full_disk(*args: object) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(pipelines.cli.simulate_cmd, "write_summary", full_disk)  # once a traceback
    out = tmp_path / "out"
    code, stdout, err = simulate([str(sequence), "--fps", "60", "--tracker", "oracle", "--out", str(out)], capsys)
    assert code == 1 and stdout == ""
    assert err == f"gimbaltrack simulate: error: cannot write the results in {out}: No space left on device\n"


def test_a_read_only_output_folder_fails_before_the_run(sequence: Path, tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch,
                                                        capsys: pytest.CaptureFixture[str]) -> None:
    import os

    out = tmp_path / "out"
    real_access = os.access
    monkeypatch.setattr(os, "access", lambda path, mode: path != out and real_access(path, mode))  # as on a ro mount
    started = time.monotonic()
    code, stdout, err = simulate([str(sequence), "--fps", "1", "--out", str(out)], capsys)  # 12 s of run
    assert time.monotonic() - started < 6  # once found only when the results were written, as a traceback
    assert (code, stdout) == (2, "")
    assert err == f"gimbaltrack simulate: error: cannot write in output folder {out}: read-only or no permission\n"


@pytest.mark.parametrize("backbone, head, wrong", [
    (b"junk!", fake_onnx.head_bytes(), "nanotrack_backbone_sim.onnx: not a readable ONNX network"),
    (fake_onnx.head_bytes(), fake_onnx.backbone_bytes(), "nanotrack_backbone_sim.onnx: not NanoTrack's backbone"),
    (fake_onnx.backbone_bytes(), fake_onnx.backbone_bytes(), "nanotrack_head_sim.onnx: not NanoTrack's neck/head"),
])
def test_wrong_model_files_are_named_in_one_line(backbone: bytes, head: bytes, wrong: str, sequence: Path,
                                                 tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    models = fake_onnx.write_nanotrack_files(tmp_path / "models", backbone, head)  # once a cv2.error traceback
    code, stdout, err = simulate([str(sequence), "--fps", "60", "--tracker", "nanotrack", "--model-dir", str(models)],
                                 capsys)
    assert code == 2 and stdout == ""
    assert err.startswith("gimbaltrack simulate: error: NanoTrack") and wrong in err and err.count("\n") == 1


def test_help_lists_trackers_defaults_and_examples(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["simulate", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "oracle" in text and "dcf" in text and "csrt" in text
    assert ("(default: default = nanovit on the model files shipped with gimbaltrack, or on --model-dir's where "
            "it holds them all, or dcf where they cannot be loaded)") in text
    assert "(default: none, nothing is written)" in text
    assert "examples: gimbaltrack simulate" in text


def test_sigterm_exits_143_and_keeps_the_outputs_so_far(sequence: Path, tmp_path: Path) -> None:
    out = tmp_path / "out"

    def running(process: subprocess.Popen[str]) -> bool:
        started = wait_until(out.is_dir, 30)  # --out is made just before the run
        time.sleep(1.0)
        return started

    code, stdout, stderr = signalled(cli_command("simulate", str(sequence), "--fps", "2", "--out", str(out)),
                                     running, cwd=ROOT, env=subprocess_env())
    assert code == 143 and stdout == ""
    assert stderr == (f"gimbaltrack simulate: note: stopped before the end; the outputs so far are in {out} "
                      "(no summary.json)\n"
                      "gimbaltrack simulate: terminated (SIGTERM)\n")
    assert sorted(p.name for p in out.iterdir()) == ["annotated.avi", "can.log", "plot.png", "telemetry.jsonl"]
    assert (out / "telemetry.jsonl").read_text().count("\n") >= 2  # 2 fps for 1 s
    assert (out / "can.log").stat().st_size > 0


@pytest.mark.parametrize("bad", ["missing", "no_frames", "no_truth"])
def test_a_bad_sequence_creates_no_out_folder(bad: str, sequence: Path, tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    """The sequence is checked before --out is made, as ``track`` checks its source (the folder
    was once left behind, empty, by a run that never started)."""
    folder, out = tmp_path / bad, tmp_path / "out" / "run"
    if bad != "missing":
        folder.mkdir()
    if bad == "no_truth":
        shutil.copy(sequence / "1.png", folder / "1.png")
    code, stdout, err = simulate([str(folder), "--out", str(out)], capsys)
    assert (code, stdout, err.count("\n")) == (2, "", 1) and err.startswith("gimbaltrack simulate: error: ")
    assert not (tmp_path / "out").exists()


def test_a_start_box_outside_the_central_view_is_pointed_at(sequence: Path, tmp_path: Path,
                                                             capsys: pytest.CaptureFixture[str]) -> None:
    """A 320x180 view of the 640x360 frame misses the subject at x = 0.2 width from the centre (once
    refused: "lies outside the 320x180 frame"); the gimbal now starts pointed at it."""
    out = tmp_path / "out"
    code, _, err = simulate([str(sequence), "--size", "320x180", "--fps", "60", "--json", "--out", str(out)],
                            capsys)
    assert (code, err) == (0, "")
    summary = json.loads((out / "summary.json").read_text())
    assert summary["out_of_view"] == 0.0 and summary["time_to_first_centre"] == 0.0 and summary["loop"] == "closed"
    assert sorted(p.name for p in out.iterdir()) == ["annotated.avi", "can.log", "plot.png", "summary.json",
                                                     "telemetry.jsonl"]
