"""A Ctrl-C or SIGTERM in the first milliseconds, while the console script imports the command's
modules (before ``app.main`` has its handlers), is one line and the usual exit status."""
from __future__ import annotations

import signal
import subprocess
import sys

import pytest

from gimbal.signals import TERMINATING_SIGNALS
from tests.support import subprocess_env

# What the console script runs, after a finder that sends the signal the moment the command's
# shared module starts loading: the signal lands in the middle of the command's imports.
SCRIPT = """
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
    done = subprocess.run([sys.executable, "-c", SCRIPT.replace("{signal}", name)], capture_output=True,
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
