"""A path option given the wrong kind of thing that exists (a folder for ``--groundtruth``, a file
for ``--model-dir``) says so, rather than "no such file" about a path the user can see."""
from __future__ import annotations

from pathlib import Path

import pytest

from pipelines.cli import main


def test_a_folder_given_as_the_groundtruth_file_is_named_a_folder(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["eval", str(tmp_path), "--groundtruth", str(tmp_path)])
    err = capsys.readouterr().err.splitlines()[-1]
    assert exit_.value.code == 2
    assert err == f"gimbaltrack eval: error: argument --groundtruth: {str(tmp_path)!r} is a folder, not a file"


def test_a_file_given_as_the_model_folder_is_named_a_file(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    model = tmp_path / "nanotrack_backbone_sim.onnx"
    model.write_bytes(b"")
    with pytest.raises(SystemExit) as exit_:
        main(["eval", str(tmp_path), "--model-dir", str(model)])
    err = capsys.readouterr().err.splitlines()[-1]
    assert exit_.value.code == 2
    assert err == f"gimbaltrack eval: error: argument --model-dir: {str(model)!r} is a file, not a folder"
