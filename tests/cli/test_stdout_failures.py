"""Results that cannot be written (stdout on a full disk) are a one-line error and exit 1."""
from __future__ import annotations

import os
import subprocess

import pytest

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
