"""``gimbaltrack eval``: text and JSON output, and one-line errors."""
import json
import subprocess
from pathlib import Path

import cv2
import pytest

from tests.support import cli_command
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
