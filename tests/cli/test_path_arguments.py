"""Path arguments that cannot mean what was typed are refused in one line, before anything is
opened or written."""
from __future__ import annotations

from pathlib import Path

import pytest

from pipelines.cli import main


# An empty path argument is refused in one line (exit 2): ``Path("")`` is the current folder, so
# ``track ""`` once tracked the images of whatever folder it was run in, and ``eval ""`` scored it.
@pytest.mark.parametrize("args, words", [
    (["track", "", "--no-video", "--quiet"], "an empty source"),
    (["track", " ", "--no-video", "--quiet"], "an empty source"),
    (["eval", ""], "an empty sequence path"),
    (["simulate", ""], "an empty sequence path"),
    (["decode", ""], "an empty path"),
    (["replay", ""], "an empty path"),
])
def test_an_empty_path_is_a_one_line_error(args: list[str], words: str, tmp_path: Path,
                                           monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(tmp_path)  # a folder with nothing to find in it
    assert main([*args, *(["--out", str(tmp_path / "out")] if args[0] == "track" else [])]) == 2
    err = capsys.readouterr().err
    assert words in err and err.count("\n") == 1, err
    assert not (tmp_path / "out").exists()  # refused before any output


def test_an_empty_model_dir_is_refused() -> None:
    import argparse

    from pipelines.cli.common import existing_dir
    with pytest.raises(argparse.ArgumentTypeError, match="an empty path"):
        existing_dir("")  # once the current folder, searched for model files


# A path option given the wrong kind of thing that exists (a folder for ``--groundtruth``, a file
# for ``--model-dir``) says so, rather than "no such file" about a path the user can see.
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
