"""Start-up stays light: ``gimbaltrack --help`` and a ``gimbal ... --print-packet`` load neither
OpenCV nor SciPy (with them every command took ~3 s to start on this project's machine)."""
from __future__ import annotations

import argparse
import importlib
import json
import subprocess
import sys

import pytest

from pipelines.cli import app
from tests.support import subprocess_env

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
