"""An empty path argument is refused in one line (exit 2): ``Path("")`` is the current folder, so
``track ""`` once tracked the images of whatever folder it was run in, and ``eval ""`` scored it."""
from __future__ import annotations

from pathlib import Path

import pytest

from pipelines.cli import main


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
