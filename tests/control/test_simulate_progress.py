"""``gimbaltrack simulate`` shows its progress (issue #26: a run sat silent until its report)."""
from __future__ import annotations

import io
import sys
from pathlib import Path

import pytest

import pipelines.cli.app
from pipelines.cli import main


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_simulate_shows_its_progress_on_a_terminal(sequence: Path, monkeypatch: pytest.MonkeyPatch,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(pipelines.cli.app, "SUBCOMMAND_MODULES", ["pipelines.cli.simulate_cmd"])
    for quiet in ([], ["--quiet"]):
        terminal = Terminal()
        monkeypatch.setattr(sys, "stderr", terminal)
        assert main(["simulate", str(sequence), "--tracker", "oracle", "--fps", "30", *quiet]) == 0
        lines = terminal.getvalue().split("\r")
        if quiet:
            assert lines == [""]
        else:
            assert "] 100% 12/12 frames" in lines[-1] and lines[-1].rstrip().endswith("fps done")
    capsys.readouterr()
    assert main(["simulate", str(sequence), "--tracker", "oracle", "--fps", "60"]) == 0
    assert capsys.readouterr().err == ""  # not a terminal: no progress among the errors of a log
