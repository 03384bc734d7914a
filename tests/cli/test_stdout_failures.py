"""Results that cannot be written (stdout on a full disk) are a one-line error and exit 1; a reader
that went away (a broken pipe) leaves the run's own exit status."""
from __future__ import annotations

import io
import os
import subprocess
import sys
from pathlib import Path

import pytest

import pipelines.cli.decode_cmd
from pipelines.cli import main
from tests.support import cli_command, subprocess_env


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
@pytest.mark.parametrize("args", [["decode", "--hex", "AA"], ["gimbal", "move", "--yaw", "3", "--print-packet"]])
def test_a_full_stdout_is_one_line_and_exit_1(args: list[str]) -> None:
    with open("/dev/full", "w") as full:
        done = subprocess.run(cli_command(*args), stdout=full, stderr=subprocess.PIPE, text=True,
                              env=subprocess_env(), timeout=60)
    assert done.returncode == 1
    assert done.stderr.endswith(": error: [Errno 28] No space left on device\n")
    assert done.stderr.count("\n") == 1


def test_a_broken_pipe_at_the_end_keeps_the_runs_exit_status(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    class ReaderGone(io.StringIO):
        def __init__(self, fd: int) -> None:
            super().__init__()
            self._fd = fd

        def fileno(self) -> int:  # where the pipe's end is pointed once the reader has gone
            return self._fd

        def flush(self) -> None:
            raise BrokenPipeError(32, "Broken pipe")

    with open(tmp_path / "stdout", "w") as target:
        monkeypatch.setattr(sys, "stdout", ReaderGone(target.fileno()))
        monkeypatch.setattr(pipelines.cli.decode_cmd, "run", lambda args: 130)  # e.g. track after Ctrl-C
        assert main(["decode", "--hex", "AA"]) == 130


def test_an_oserror_without_words_is_named(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    def run(args: object) -> int:
        raise TimeoutError

    monkeypatch.setattr(pipelines.cli.decode_cmd, "run", run)
    assert main(["decode", "--hex", "AA"]) == 1
    assert capsys.readouterr().err == "gimbaltrack decode: error: TimeoutError\n"
