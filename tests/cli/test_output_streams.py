"""Standard streams that fail under a run (closed, full, or a reader gone): the results a script
parses stay clean and the exit status says what happened."""
from __future__ import annotations

import io
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import pipelines.cli.decode_cmd
from pipelines.cli import main
from tests.support import cli_command, subprocess_env


# A closed stderr (``2>&-``): Python gives ``sys.stderr = None``, and ``print(..., file=None)``
# writes to stdout, so the one-line errors were once mixed into the results a script parses, and
# ``track`` died of an AttributeError nobody could see. Errors now go nowhere, the exit status still
# tells the failure, and fd 2 is held so that no file opened later takes it.
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


# Results that cannot be written (stdout on a full disk) are a one-line error and exit 1; a reader
# that went away (a broken pipe) leaves the run's own exit status.
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


def _closed_stdout(command: list[str]) -> list[str]:
    """``command`` run with its stdout closed, as ``>&-`` does in a shell."""
    return ["sh", "-c", '"$@" >&-', "sh", *command]


CLOSED = ": error: [Errno 9] stdout is closed: the results went nowhere\n"


def test_a_closed_stdout_is_one_line_and_exit_1() -> None:
    """Python leaves ``sys.stdout`` None when fd 1 is closed: the results were once dropped by
    print() and the final flush was an AttributeError traceback."""
    done = subprocess.run(_closed_stdout(cli_command("decode", "--hex", "AA")), stderr=subprocess.PIPE,
                          text=True, env=subprocess_env(), timeout=60)
    assert (done.returncode, done.stderr) == (1, f"gimbaltrack decode{CLOSED}")


def test_track_with_a_closed_stdout_keeps_its_outputs(tmp_path: Path) -> None:
    command = cli_command("track", "samples/demo.mp4", "--roi", "138,152,64,96", "--no-video", "--quiet",
                          "--max-frames", "5", "--out", str(tmp_path))
    done = subprocess.run(_closed_stdout(command), stderr=subprocess.PIPE, text=True, env=subprocess_env(),
                          timeout=120)
    assert (done.returncode, done.stderr) == (1, f"gimbaltrack track{CLOSED}")
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["frames"] == 5 and summary["speed_commands"]["stop_release_sent"]
    assert len((tmp_path / "telemetry.jsonl").read_text().splitlines()) == 5  # and nothing else landed on fd 1


@pytest.mark.parametrize("error", [OSError(28, "No space left on device"), OSError(9, "Bad file descriptor")])
def test_results_that_cannot_be_written_leave_a_stopped_runs_status(
        error: OSError, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """Ctrl-C's 130 (SIGTERM's 143, ...) stands when the report then cannot be written; it was 1."""
    class Unwritable(io.StringIO):
        def fileno(self) -> int:  # where stdout is pointed once it has failed
            return target.fileno()

        def flush(self) -> None:
            raise error

    def run(args: object) -> int:
        print("interrupted (SIGINT): the report")
        return 130

    monkeypatch.setattr(pipelines.cli.decode_cmd, "run", run)
    with open(tmp_path / "stdout", "w") as target:
        monkeypatch.setattr(sys, "stdout", Unwritable())
        assert main(["decode", "--hex", "AA"]) == 130
    assert capsys.readouterr().err == f"gimbaltrack decode: error: {error}\n"


def test_help_to_a_closed_stdout_is_one_line_and_exit_1() -> None:
    """argparse's --help leaves by SystemExit(0): the text it wrote was flushed only at exit,
    an 'Exception ignored' traceback and exit 120."""
    done = subprocess.run(_closed_stdout(cli_command("decode", "--help")), stderr=subprocess.PIPE,
                          text=True, env=subprocess_env(), timeout=60)
    assert (done.returncode, done.stderr) == (1, f"gimbaltrack{CLOSED}")


def test_an_error_after_results_to_a_closed_stdout_keeps_its_status(tmp_path: Path) -> None:
    """A run that printed results and then failed in its own words (a log unreadable after two
    frames): its status and its line stand, and the unwritten results are one more line."""
    log = tmp_path / "cut.log"
    log.write_text("(0.0) can0 223#AA1A000300000000\n(0.1) can0 223#0102030405060708\nnot a frame\n")
    done = subprocess.run(_closed_stdout(cli_command("decode", str(log))), stderr=subprocess.PIPE,
                          text=True, env=subprocess_env(), timeout=60)
    assert done.returncode == 2
    assert done.stderr.splitlines()[1:] == [f"gimbaltrack decode{CLOSED}".rstrip("\n")]
    assert "unreadable after frame 2" in done.stderr.splitlines()[0]
