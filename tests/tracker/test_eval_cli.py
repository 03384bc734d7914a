"""``gimbaltrack eval``: text and JSON output, and one-line errors."""
import json
import re
import subprocess
from pathlib import Path

import cv2
import pytest

from tests.support import cli_command, signalled, write_clip
from tracker.synthetic import render_sequence


def gimbaltrack(argv: list[str]) -> subprocess.CompletedProcess:
    """The real command in a fresh interpreter (exit code, stdout and stderr as a user sees them)."""
    return subprocess.run(cli_command(*argv), capture_output=True, text=True, timeout=120)


@pytest.fixture(scope="module")
def otb_dir(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("synthetic_otb")
    seq = render_sequence(frames=30, seed=3)
    (folder / "img").mkdir()
    for i, frame in enumerate(seq.frames, 1):
        cv2.imwrite(str(folder / "img" / f"{i:04d}.png"), frame)
    (folder / "groundtruth_rect.txt").write_text("".join("\t".join(f"{v:.1f}" for v in b) + "\n" for b in seq.boxes))
    return folder


def test_json_has_one_object_per_sequence_and_a_summary(otb_dir):
    captured = gimbaltrack(["eval", str(otb_dir), str(otb_dir), "--json"])
    assert captured.returncode == 0
    lines = [json.loads(line) for line in captured.stdout.splitlines()]
    assert len(lines) == 3
    assert lines[0]["sequence"] == otb_dir.name and lines[0]["frames"] == 30
    summary = lines[-1]
    assert {"prec20", "auc", "fps"} <= summary.keys()
    assert summary["auc"] > 0.6 and summary["prec20"] == 1.0 and summary["fps"] > 0
    assert "30/30 frames" in captured.stderr


def test_text_output_has_a_row_per_sequence_and_overall(otb_dir):
    captured = gimbaltrack(["eval", str(otb_dir), "--tracker", "kcf"])
    assert captured.returncode == 0
    rows = captured.stdout.splitlines()
    assert len(rows) == 2
    assert rows[0].startswith(otb_dir.name) and "prec20" in rows[0] and "auc" in rows[0]
    assert rows[1].startswith("overall (kcf)") and "fps" in rows[1]


@pytest.mark.parametrize("argv, message", [
    (["eval", "/no/such/dir"], "no such sequence"),
    (["eval", "{tmp}"], "no image frames"),
    (["eval", "{otb}", "--tracker", "nope"], "unknown tracker 'nope'"),
    (["eval", "{otb}", "--tracker", "nano", "--model-dir", "{tmp}"], "nanotrack_backbone"),
])
def test_bad_input_is_one_line_and_nonzero(argv, message, otb_dir, tmp_path):
    argv = [a.format(tmp=tmp_path, otb=otb_dir) for a in argv]
    captured = gimbaltrack(argv)
    assert captured.returncode != 0
    err = captured.stderr.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("gimbaltrack eval: error:") and message in err[0]


def test_image_folder_without_groundtruth_is_refused(tmp_path):
    cv2.imwrite(str(tmp_path / "0001.png"), render_sequence(frames=1).frames[0])
    captured = gimbaltrack(["eval", str(tmp_path)])
    assert captured.returncode != 0 and "no ground truth" in captured.stderr


def test_a_video_without_groundtruth_names_every_file_accepted(tmp_path):
    clip = write_clip(tmp_path / "clip.avi", render_sequence(frames=3).frames, 30.0, "MJPG")
    captured = gimbaltrack(["eval", str(clip)])
    assert captured.returncode == 2
    assert captured.stderr == (f"gimbaltrack eval: error: {clip}: no ground truth (groundtruth_rect.txt, "
                               "groundtruth.txt, clip.txt or clip_groundtruth.txt beside the video)\n")


def test_nanotrack_without_model_files_names_the_option(otb_dir):
    captured = gimbaltrack(["eval", str(otb_dir), "--tracker", "nanotrack"])
    assert captured.returncode == 2 and "pass a model directory (--model-dir" in captured.stderr


def test_one_sequence_and_the_overall_print_the_same_scores(tmp_path):
    """53 of 54 frames within 20 px: 0.98148..., which must not read 0.981 once and 0.982 once."""
    seq = render_sequence(frames=54, seed=3)
    (tmp_path / "img").mkdir()
    for i, frame in enumerate(seq.frames, 1):
        cv2.imwrite(str(tmp_path / "img" / f"{i:04d}.png"), frame)
    boxes = [*seq.boxes[:-1], (0.0, 0.0, 10.0, 10.0)]  # the last box far from the subject
    (tmp_path / "groundtruth_rect.txt").write_text("".join(",".join(f"{v:.1f}" for v in b) + "\n" for b in boxes))
    captured = gimbaltrack(["eval", str(tmp_path)])
    assert captured.returncode == 0
    rows = captured.stdout.splitlines()
    scores = [re.search(r"prec20 (\S+)  auc (\S+)", row).groups() for row in rows]
    assert scores[0] == scores[1] and scores[0][0] == "0.9815"


def test_help_states_defaults_and_examples():
    text = " ".join(gimbaltrack(["eval", "--help"]).stdout.split())
    assert "(default: default = nanotrack when --model-dir holds its files, else dcf)" in text
    assert "nanotrack_v2/ (default: none)" in text and "examples: gimbaltrack eval" in text


def test_sigterm_exits_143_with_a_note(tmp_path):
    frames = render_sequence(frames=2, seed=3)
    (tmp_path / "img").mkdir()
    count = 3000  # the same two images over and over: a run of several seconds
    for i in range(1, 3):
        cv2.imwrite(str(tmp_path / f"{i}.png"), frames.frames[i - 1])
    for i in range(1, count + 1):
        (tmp_path / "img" / f"{i:05d}.png").symlink_to(tmp_path / f"{i % 2 + 1}.png")
    box = ",".join(f"{v:.1f}" for v in frames.boxes[0])
    (tmp_path / "groundtruth_rect.txt").write_text(f"{box}\n" * count)
    code, stdout, stderr = signalled(cli_command("eval", str(tmp_path), "--tracker", "csrt"),
                                     lambda process: process.stderr.readline().startswith("["))  # progress
    assert code == 143 and stdout == ""
    assert stderr.splitlines()[-1] == "gimbaltrack eval: terminated (SIGTERM)" and "Traceback" not in stderr
