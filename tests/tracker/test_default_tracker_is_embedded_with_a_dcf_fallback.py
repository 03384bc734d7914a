"""The default tracker runs on the model files shipped inside the package, with no --model-dir; where
they cannot be loaded it is the correlation filter, with one warning line."""
import json
import shutil
import subprocess
import sys

import pytest

from tests import fake_onnx
from tests.support import cli_command
from tests.tracker.test_eval_cli import write_otb
from tracker import registry
from tracker.registry import DEFAULT_MODEL_TRACKER, EMBEDDED_MODELS, ModelFallbackWarning, make_tracker


def test_the_default_runs_on_the_embedded_model_files_with_their_licence():
    subject = make_tracker()
    assert subject.name == DEFAULT_MODEL_TRACKER
    assert subject.model == str(EMBEDDED_MODELS)
    folder = EMBEDDED_MODELS / "nanotrack_v3"
    assert sorted(p.name for p in folder.glob("*.onnx")) == ["nanotrack_backbone.onnx", "nanotrack_head.onnx"]
    assert any(folder.glob("LICENSE*")) and (folder / "PROVENANCE.md").is_file()


def test_the_package_data_ships_the_model_folder():
    text = (EMBEDDED_MODELS.parent.parent / "pyproject.toml").read_text()
    assert '"tracker" = ["models/*/*"]' in text


def test_a_damaged_embedded_file_falls_back_to_dcf_with_a_warning(tmp_path, monkeypatch):
    shutil.copytree(EMBEDDED_MODELS, tmp_path / "models")
    (tmp_path / "models" / "nanotrack_v3" / "nanotrack_head.onnx").write_bytes(b"junk!")
    monkeypatch.setattr(registry, "EMBEDDED_MODELS", tmp_path / "models")
    with pytest.warns(ModelFallbackWarning, match=r"nanotrack3\) cannot be loaded, so dcf runs instead: .*nanotrack_head"):
        subject = make_tracker()
    assert subject.name == "dcf" and subject.model is None


def test_without_onnxruntime_the_default_falls_back_to_dcf(monkeypatch):
    monkeypatch.setitem(sys.modules, "onnxruntime", None)  # import fails as if it were not installed
    with pytest.warns(ModelFallbackWarning, match="onnxruntime"):
        assert make_tracker().name == "dcf"


def test_a_named_model_tracker_is_not_replaced_by_dcf(monkeypatch):
    monkeypatch.setitem(sys.modules, "onnxruntime", None)
    with pytest.raises(ImportError):
        make_tracker("nanotrack3")


def test_a_model_dir_holding_the_defaults_files_is_used(tmp_path):
    models = fake_onnx.onnx_model_files(tmp_path)
    subject = make_tracker("default", models)
    assert subject.name == DEFAULT_MODEL_TRACKER and subject.model == str(models)


def test_a_model_dir_without_them_leaves_the_default_on_the_embedded_files(tmp_path):
    assert make_tracker("default", tmp_path).model == str(EMBEDDED_MODELS)


def test_eval_json_names_the_tracker_and_its_model(tmp_path):
    otb = write_otb(tmp_path / "otb", frames=5)
    captured = subprocess.run(cli_command("eval", str(otb), "--json"), capture_output=True, text=True, timeout=120)
    assert captured.returncode == 0, captured.stderr
    summary = json.loads(captured.stdout.splitlines()[-1])
    assert summary["tracker"] == DEFAULT_MODEL_TRACKER and summary["model"] == str(EMBEDDED_MODELS)


def test_the_cli_says_the_fallback_in_one_line_and_carries_on(tmp_path):
    otb = write_otb(tmp_path / "otb", frames=5)
    hide = "import sys; sys.modules['onnxruntime'] = None; from pipelines.cli import main; sys.exit(main())"
    command = [sys.executable, "-c", hide, "eval", str(otb), "--json"]
    captured = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert captured.returncode == 0, captured.stderr
    warning = [line for line in captured.stderr.splitlines() if "warning" in line]
    assert len(warning) == 1 and warning[0].startswith("gimbaltrack: warning: the default tracker's model")
    assert "Traceback" not in captured.stderr
    assert json.loads(captured.stdout.splitlines()[-1])["tracker"] == "dcf"
