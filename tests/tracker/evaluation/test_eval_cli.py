"""``gimbaltrack eval``: text and JSON output, and one-line errors."""
import json
import re
import subprocess
from pathlib import Path

import cv2
import pytest

from tests import fake_onnx
from tests.support import cli_command, signalled, write_clip
from tests.tracker.evaluation.batch_helpers import long_sequence
from tracker.evaluation.synthetic import render_sequence


def gimbaltrack(argv: list[str]) -> subprocess.CompletedProcess:
    """The real command in a fresh interpreter (exit code, stdout and stderr as a user sees them)."""
    return subprocess.run(cli_command(*argv), capture_output=True, text=True, timeout=120)


def write_otb(folder: Path, frames: int = 30, first: str | None = None) -> Path:
    """A rendered OTB-style sequence in ``folder``; ``first`` replaces the first ground-truth line."""
    seq = render_sequence(frames=frames, seed=3)
    (folder / "img").mkdir(parents=True)
    for i, frame in enumerate(seq.frames, 1):
        cv2.imwrite(str(folder / "img" / f"{i:04d}.png"), frame)
    lines = ["\t".join(f"{v:.1f}" for v in b) for b in seq.boxes]
    (folder / "groundtruth_rect.txt").write_text("".join(line + "\n" for line in [first or lines[0], *lines[1:]]))
    return folder


@pytest.fixture(scope="module")
def otb_dir(tmp_path_factory) -> Path:
    return write_otb(tmp_path_factory.mktemp("synthetic_otb"))


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


def one_line_error(captured: subprocess.CompletedProcess, *words: str) -> None:
    """Exit 2 with one ``gimbaltrack eval: error:`` line on stderr holding ``words``."""
    err = captured.stderr.strip().splitlines()
    assert captured.returncode == 2 and len(err) == 1, captured.stderr
    assert err[0].startswith("gimbaltrack eval: error:") and all(w in err[0] for w in words), err[0]


@pytest.mark.parametrize("first", ["NaN,NaN,NaN,NaN", "0,0,0,0", "10,10,0,20"])
def test_a_missing_or_empty_first_box_is_one_line(tmp_path, first):
    """NaN: once a traceback from the tracker; 0,0,0,0: once scored (prec20 0.05) without a word."""
    write_otb(tmp_path / "seq", frames=3, first=first)
    captured = gimbaltrack(["eval", str(tmp_path / "seq"), "--json"])
    one_line_error(captured, "seq: the first ground-truth box", "missing or empty")
    assert captured.stdout == ""


def test_groundtruth_shorter_than_the_frames_is_refused(tmp_path):
    folder = write_otb(tmp_path / "seq", frames=4)
    gt = folder / "groundtruth_rect.txt"
    gt.write_text("".join(gt.read_text().splitlines(keepends=True)[1:]))  # boxes for frames 2-4 only
    one_line_error(gimbaltrack(["eval", str(folder)]), "3 boxes but", "has 4 frames")  # once scored as frames 1-3


def test_an_unreadable_frame_skips_its_sequence_and_the_others_are_summarised(tmp_path, otb_dir):
    broken = write_otb(tmp_path / "broken", frames=6)
    (broken / "img" / "0004.png").write_bytes(b"not a png")
    captured = gimbaltrack(["eval", str(otb_dir), str(broken), str(otb_dir), "--json"])
    assert captured.returncode == 2  # once a traceback after the first row, and no summary
    rows = [json.loads(line) for line in captured.stdout.splitlines()]
    assert [r.get("sequence") for r in rows] == [otb_dir.name, otb_dir.name, None] and rows[-1]["sequences"] == 2
    errors = [line for line in captured.stderr.splitlines() if "error" in line]
    assert errors == [f"gimbaltrack eval: error: broken: cannot read frame 4 ({broken / 'img' / '0004.png'}) "
                      "(skipped; the summary covers the other sequences)"]
    one_line_error(gimbaltrack(["eval", str(broken)]), "broken: cannot read frame 4")


def test_a_truncated_video_is_one_line_naming_the_frame(tmp_path):
    seq = render_sequence(frames=30, seed=3)
    full = write_clip(tmp_path / "full.avi", seq.frames, 30.0, "MJPG")
    data = full.read_bytes()
    (tmp_path / "clip.avi").write_bytes(data[:len(data) // 2])  # the header still says 30 frames
    (tmp_path / "clip.txt").write_text("".join(",".join(f"{v:.1f}" for v in b) + "\n" for b in seq.boxes))
    captured = gimbaltrack(["eval", str(tmp_path / "clip.avi")])
    one_line_error(captured, "clip: cannot read frame", "of the 30 in", "truncated or damaged")  # once a traceback
    assert captured.stdout == ""


@pytest.mark.parametrize("tracker", ["nanotrack", "nano"])  # the default reads NanoTrack v3, not these v2 files
@pytest.mark.parametrize("backbone, head, wrong", [
    (b"junk!", b"junk!", "nanotrack_backbone_sim.onnx: not a readable ONNX network"),
    (fake_onnx.head_bytes(), fake_onnx.backbone_bytes(), "nanotrack_backbone_sim.onnx: not NanoTrack's backbone"),
    (fake_onnx.backbone_bytes(), fake_onnx.backbone_bytes(), "nanotrack_head_sim.onnx: not NanoTrack's neck/head"),
])
def test_wrong_model_files_are_named_in_one_line(tmp_path, otb_dir, tracker, backbone, head, wrong):
    models = fake_onnx.write_nanotrack_files(tmp_path / "models", backbone, head)  # once a cv2.error traceback
    one_line_error(gimbaltrack(["eval", str(otb_dir), "--tracker", tracker, "--model-dir", str(models)]), wrong)


def test_a_one_frame_sequence_has_no_fps(tmp_path):
    """Nothing is timed: null in JSON (once Infinity, which strict parsers refuse), "-" in text."""
    folder = write_otb(tmp_path / "one", frames=1)
    captured = gimbaltrack(["eval", str(folder), "--json"])
    assert captured.returncode == 0

    def refuse(constant: str) -> None:
        raise ValueError(f"not JSON: {constant}")

    row, summary = (json.loads(line, parse_constant=refuse) for line in captured.stdout.splitlines())
    assert row["fps"] is None and summary["fps"] is None and summary["cpu_fps"] is None
    rows = gimbaltrack(["eval", str(folder)]).stdout.splitlines()
    assert rows[0].endswith("fps       -") and rows[1].endswith("fps       - (median)")


def test_image_folder_without_groundtruth_is_refused(tmp_path):
    cv2.imwrite(str(tmp_path / "0001.png"), render_sequence(frames=1).frames[0])
    captured = gimbaltrack(["eval", str(tmp_path)])
    assert captured.returncode != 0 and "no ground truth" in captured.stderr


def test_a_video_without_groundtruth_names_every_file_accepted(tmp_path):
    clip = write_clip(tmp_path / "clip.avi", render_sequence(frames=3).frames, 30.0, "MJPG")
    captured = gimbaltrack(["eval", str(clip)])
    assert captured.returncode == 2
    assert captured.stderr == (f"gimbaltrack eval: error: {clip}: no ground truth (groundtruth_rect.txt, "
                               "groundtruth.txt, clip.txt or clip_groundtruth.txt beside the video; or name its file "
                               "with --groundtruth)\n")


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
    assert ("(default: default = nanovit on the model files shipped with gimbaltrack, or on --model-dir's where "
            "it holds them all, or dcf where they cannot be loaded)") in text
    assert "nanotrack_v2/ (default: the files shipped with gimbaltrack)" in text and "examples: gimbaltrack eval" in text


def test_sigterm_exits_143_with_a_note(tmp_path):
    sequence = long_sequence(tmp_path / "long")
    code, stdout, stderr = signalled(cli_command("eval", str(sequence), "--tracker", "csrt"),
                                     lambda process: process.stderr.readline().startswith("["))  # progress
    assert code == 143 and stdout == ""
    assert stderr.splitlines()[-1] == "gimbaltrack eval: terminated (SIGTERM)" and "Traceback" not in stderr


def test_a_videos_groundtruth_can_be_named(tmp_path):
    """A video whose ground truth lives elsewhere (the shared data's bag.avi and sequences/vot_bag)
    scores as with the same file beside it; a second sequence, or a file that is not text, is refused."""
    seq = render_sequence(frames=20, seed=3)
    clip = write_clip(tmp_path / "clip.avi", seq.frames, 30.0, "MJPG")
    truth = tmp_path / "elsewhere" / "groundtruth.txt"
    truth.parent.mkdir()
    truth.write_text("".join(",".join(f"{v:.1f}" for v in b) + "\n" for b in seq.boxes))
    named = gimbaltrack(["eval", str(clip), "--groundtruth", str(truth), "--json"])
    assert named.returncode == 0
    (tmp_path / "clip.txt").write_text(truth.read_text())
    beside = gimbaltrack(["eval", str(clip), "--json"])
    scores = [[{k: row[k] for k in ("sequence", "frames", "prec20", "auc")} for row in map(json.loads, run.stdout.splitlines()[:1])]
              for run in (named, beside)]
    assert scores[0] == scores[1] and scores[0][0]["frames"] == 20
    one_line_error(gimbaltrack(["eval", str(clip), str(clip), "--groundtruth", str(truth)]), "--groundtruth is for one sequence")
    one_line_error(gimbaltrack(["eval", str(clip), "--groundtruth", str(clip)]), f"{clip}: not a text file of boxes")
