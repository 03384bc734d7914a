"""The console script's first moments: what it imports, and what a signal or an early error does
before the command's handlers are set."""
from __future__ import annotations

import argparse
import importlib
import json
import signal
import subprocess
import sys

import pytest

import pipelines.cli.app
import pipelines.cli.eval_cmd
from gimbal.signals import TERMINATING_SIGNALS
from pipelines.cli import app, main
from tests.support import subprocess_env


# Start-up stays light: ``gimbaltrack --help`` and a ``gimbal ... --print-packet`` load neither
# OpenCV nor SciPy (with them every command took ~3 s to start on this project's machine).
HEAVY = ("cv2", "scipy", "filterpy", "matplotlib")
SCRIPT = """
import contextlib, io, json, sys
from pipelines.cli import main
with contextlib.redirect_stdout(io.StringIO()) as out:
    try:
        code = main({argv!r})
    except SystemExit as exc:
        code = exc.code
print(json.dumps({{"code": code, "out": out.getvalue(), "heavy": [m for m in {heavy!r} if m in sys.modules]}}))
"""


def _run(argv: list[str]) -> dict:
    done = subprocess.run([sys.executable, "-c", SCRIPT.format(argv=argv, heavy=HEAVY)], capture_output=True,
                          text=True, env=subprocess_env(), timeout=120)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


@pytest.mark.parametrize("argv", [
    ["--help"],
    ["gimbal", "move", "--yaw", "3.2", "--roll", "4.8", "--pitch", "6.4", "--absolute", "--time", "2",
     "--seq", "0x1122", "--print-packet"],
    ["doctor", "--help"],
])
def test_help_and_print_packet_load_neither_opencv_nor_scipy(argv: list[str]) -> None:
    result = _run(argv)
    assert result["code"] == 0 and result["out"]
    assert result["heavy"] == []


def test_the_command_list_is_complete_without_loading_the_commands() -> None:
    result = _run(["--help"])
    for name, line in app.COMMAND_HELP.items():
        assert name in result["out"] and line.split()[0] in result["out"]


@pytest.mark.parametrize("module", app.SUBCOMMAND_MODULES)
def test_each_command_line_is_the_one_its_module_registers(module: str) -> None:
    """``COMMAND_HELP`` stands in for the modules' own help lines until they load: they must agree."""
    subparsers = argparse.ArgumentParser().add_subparsers()
    importlib.import_module(module).register(subparsers)
    (choice,) = subparsers._choices_actions
    assert (choice.dest, choice.help) == (app.command_name(module), app.COMMAND_HELP[app.command_name(module)])


def test_a_command_parsed_lazily_is_the_same_command() -> None:
    argv = ["track", "clip.mp4", "--invert-yaw", "--debug"]
    lazy, eager = app.build_parser(lazy=True).parse_args(argv), app.build_parser().parse_args(argv)
    assert vars(lazy) == vars(eager) and lazy.debug is True


# A Ctrl-C or SIGTERM in the first milliseconds, while the console script imports the command's
# modules (before ``app.main`` has its handlers), is one line and the usual exit status.
# What the console script runs, after a finder that sends the signal the moment the command's
# shared module starts loading: the signal lands in the middle of the command's imports.
SIGNALLING_SCRIPT = """
import signal, sys

class SignalOnImport:
    def find_spec(self, name, path=None, target=None):
        if name == "pipelines.cli.common":
            signal.raise_signal(signal.{signal})
        return None

sys.meta_path.insert(0, SignalOnImport())
from pipelines.cli import main
sys.exit(main(["decode", "--hex", "AA"]))
"""


@pytest.mark.parametrize("name,status,words", [("SIGINT", 130, "gimbaltrack: interrupted"),
                                               ("SIGTERM", 143, "gimbaltrack: terminated (SIGTERM)")])
def test_a_signal_while_the_command_loads_is_one_line(name: str, status: int, words: str) -> None:
    done = subprocess.run([sys.executable, "-c", SIGNALLING_SCRIPT.replace("{signal}", name)], capture_output=True,
                          text=True, env=subprocess_env(), timeout=60)
    assert (done.returncode, done.stderr) == (status, words + "\n")
    assert done.stdout == ""  # the signal came first: nothing decoded


def test_importing_the_command_changes_no_signal_handling() -> None:
    code = ("import signal; before = (signal.getsignal(signal.SIGINT), signal.pthread_sigmask(signal.SIG_BLOCK, []));"
            "import pipelines.cli; "
            "assert (signal.getsignal(signal.SIGINT), signal.pthread_sigmask(signal.SIG_BLOCK, [])) == before")
    assert subprocess.run([sys.executable, "-c", code], env=subprocess_env(), timeout=60).returncode == 0


def test_the_held_signals_are_the_ones_the_command_handles() -> None:
    import pipelines.cli.process

    assert pipelines.cli.process.HELD_SIGNALS == (signal.SIGINT, *TERMINATING_SIGNALS)


def test_python_dash_m_runs_the_command() -> None:
    done = subprocess.run([sys.executable, "-m", "pipelines.cli", "decode", "--hex", "AA"], capture_output=True,
                          text=True, env=subprocess_env(), timeout=60)
    assert done.returncode == 0 and '"error": "truncated"' in done.stdout


# ``--debug`` shows the traceback of an OSError however early it comes: without it, one line.
@pytest.mark.parametrize("where", ["building", "loading", "parsing"])
def test_debug_shows_the_traceback_of_an_oserror_before_the_arguments_are_parsed(
        where: str, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """An unreadable module while the parser is built or the chosen command's module loads, or a
    folder option that cannot be looked at (EACCES on the way to it), was a one-line error even
    with --debug."""
    def denied(*args: object, **kwargs: object) -> None:
        raise PermissionError(13, "Permission denied", "/opt/somewhere")

    if where == "building":
        monkeypatch.setattr(pipelines.cli.app, "build_parser", denied)
    elif where == "loading":
        monkeypatch.setattr(pipelines.cli.app.importlib, "import_module", denied)
    else:
        monkeypatch.setattr(pipelines.cli.eval_cmd, "existing_dir", denied)
    args = ["eval", "samples/demo.mp4", "--model-dir", "/opt/somewhere"]
    assert main(args) == 1
    assert capsys.readouterr().err.endswith("error: [Errno 13] Permission denied: '/opt/somewhere'\n")
    with pytest.raises(PermissionError):
        main([*args, "--debug"])
