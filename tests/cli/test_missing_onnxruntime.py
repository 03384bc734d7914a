"""A model tracker asked for on a machine without onnxruntime: one line naming what is missing and
the way out, exit 2, no traceback; nothing written for ``track`` (the tracker is made before --out)."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

from tests import fake_onnx
from tests.support import ROOT, subprocess_env
from tests.tracker.evaluation.test_eval_cli import write_otb

WITHOUT_ONNXRUNTIME = ("import sys; sys.modules['onnxruntime'] = None; "  # `import onnxruntime` fails
                       "from pipelines.cli import main; sys.exit(main())")


def without_onnxruntime(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", WITHOUT_ONNXRUNTIME, *args], capture_output=True, text=True,
                          timeout=120, env=subprocess_env(), cwd=ROOT)


@pytest.mark.parametrize("tracker", ["nanotrack3", "nanovit", "vittrack", "fear"])
def test_eval_names_the_missing_runtime_in_one_line(tmp_path: Path, tracker: str) -> None:
    sequence = write_otb(tmp_path / "seq", frames=3)
    shipped = tracker in ("nanotrack3", "nanovit")
    model_dir = [] if shipped else ["--model-dir", str(fake_onnx.onnx_model_files(tmp_path / "models"))]
    done = without_onnxruntime("eval", str(sequence), "--tracker", tracker, *model_dir)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1, done.stderr
    assert "onnxruntime" in lines[0] and "not installed" in lines[0] and "Traceback" not in done.stderr


def test_track_names_the_missing_runtime_before_writing_anything(tmp_path: Path) -> None:
    out = tmp_path / "out"
    done = without_onnxruntime("track", str(ROOT / "samples" / "demo.mp4"), "--tracker", "nanotrack3",
                               "--roi", "138,152,64,96", "--out", str(out))
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and "onnxruntime" in lines[-1] and "Traceback" not in done.stderr, done.stderr
    assert not out.exists()


def test_eval_falls_back_to_dcf_with_one_warning_line_and_names_it(tmp_path: Path) -> None:
    """The default tracker's model needs onnxruntime: without it ``eval`` runs ``dcf``, says so once,
    and its JSON names the tracker that ran."""
    sequence = write_otb(tmp_path / "seq", frames=3)
    done = without_onnxruntime("eval", str(sequence), "--json")
    assert done.returncode == 0, done.stderr
    warnings = [line for line in done.stderr.splitlines() if "warning" in line]
    assert len(warnings) == 1 and "Traceback" not in done.stderr, done.stderr
    assert "nanovit" in warnings[0] and "onnxruntime" in warnings[0] and warnings[0].endswith("using dcf")
    assert json.loads(done.stdout.splitlines()[-1])["tracker"] == "dcf"
