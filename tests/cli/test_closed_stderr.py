"""A closed stderr (``2>&-``): Python gives ``sys.stderr = None``, and ``print(..., file=None)``
writes to stdout, so the one-line errors were once mixed into the results a script parses, and
``track`` died of an AttributeError nobody could see. Errors now go nowhere, the exit status still
tells the failure, and fd 2 is held so that no file opened later takes it."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from tests.support import cli_command, subprocess_env


def _closed_stderr(command: list[str]) -> list[str]:
    """``command`` run with its stderr closed, as ``2>&-`` does in a shell."""
    return ["sh", "-c", '"$@" 2>&-', "sh", *command]


def _run(command: list[str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(_closed_stderr(command), stdout=subprocess.PIPE, text=True, env=subprocess_env(),
                          timeout=120)


@pytest.mark.parametrize("args", [["track", "no/such/clip.mp4"], ["decode", "--hex", "zz"]])
def test_errors_stay_off_stdout(args: list[str]) -> None:
    done = _run(cli_command(*args))
    assert (done.returncode, done.stdout) == (2, "")


def test_track_runs_with_stderr_closed(tmp_path: Path) -> None:
    """Its progress line once looked up ``sys.stderr.isatty()`` on None: exit 1, no word said."""
    done = _run(cli_command("track", "samples/demo.mp4", "--roi", "138,152,64,96", "--no-video", "--quiet",
                            "--max-frames", "5", "--json", "--out", str(tmp_path)))
    assert done.returncode == 0
    assert json.loads(done.stdout)["frames"] == 5
    assert json.loads((tmp_path / "summary.json").read_text())["frames"] == 5


def test_a_file_opened_later_does_not_take_fd_2(tmp_path: Path) -> None:
    """What C code (OpenCV, FFmpeg) writes to fd 2 must not land in an output file."""
    out = tmp_path / "out.txt"
    script = ("import os, sys\nfrom pipelines.cli import main\nstatus = main(['decode', '--hex', 'zz'])\n"
              "with open(sys.argv[1], 'w') as f:\n    os.write(2, b'noise')\nsys.exit(status)")
    done = _run([sys.executable, "-c", script, str(out)])
    assert (done.returncode, done.stdout, out.read_text()) == (2, "", "")
