"""``gimbaltrack eval --scheduler``: sequences scored on a Dask cluster (a LocalCluster of two
one-thread workers started here), and the one-line errors when Dask cannot be used."""
from __future__ import annotations

import json
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest
from distributed import LocalCluster

from pipelines.cli.eval_cmd import score_all
from tests.support import cli_command, free_udp_port, subprocess_env
from tests.tracker.evaluation.batch_helpers import scores, write_otb
from tracker.evaluation.datasets import load_sequence


@pytest.fixture(scope="module")
def cluster() -> Iterator[LocalCluster]:
    """Two workers of one thread in this process, reachable over TCP from a command's process."""
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, protocol="tcp", host="127.0.0.1",
                      dashboard_address=None) as local:
        yield local


@pytest.fixture(scope="module")
def folders(tmp_path_factory) -> list[Path]:
    root = tmp_path_factory.mktemp("dask")
    return [write_otb(root / f"seq{seed}", frames, seed) for seed, frames in ((3, 30), (5, 20), (7, 35))]


def run(*argv: str, env: dict[str, str] | None = None, python: str = "") -> subprocess.CompletedProcess:
    command = cli_command(*argv)
    if python:
        command[2] = python + command[2]
    return subprocess.run(command, capture_output=True, text=True, timeout=180, env=env or subprocess_env())


def test_the_cluster_gives_the_boxes_and_scores_of_a_serial_run(folders, cluster):
    sequences = [load_sequence(f) for f in folders]
    on_dask = score_all(sequences, "default", scheduler=cluster.scheduler_address)
    assert all(o.error is None for o in on_dask)
    assert scores(on_dask) == scores(score_all(sequences, "default"))


def test_the_command_prints_the_serial_rows_in_input_order(folders, cluster):
    args = ["eval", str(folders[2]), str(folders[0]), str(folders[1]), "--json"]
    serial, on_dask = run(*args), run(*args, "--scheduler", cluster.scheduler_address)
    assert serial.returncode == on_dask.returncode == 0, on_dask.stderr
    untimed = [[{k: v for k, v in json.loads(line).items() if "fps" not in k} for line in c.stdout.splitlines()]
               for c in (serial, on_dask)]
    assert untimed[0] == untimed[1] and [r.get("sequence") for r in untimed[1]] == ["seq7", "seq3", "seq5", None]
    assert "3/3 sequences" in on_dask.stderr and "Traceback" not in on_dask.stderr


def one_line(captured: subprocess.CompletedProcess, text: str) -> None:
    assert captured.returncode == 2 and captured.stdout == ""
    assert captured.stderr.splitlines() == [f"gimbaltrack eval: error: {text}"], captured.stderr


def test_without_dask_installed_the_option_names_the_extra(folders):
    blocked = "import sys; sys.modules['distributed'] = None; "  # as if the package were not installed
    one_line(run("eval", str(folders[0]), "--scheduler", "tcp://127.0.0.1:8786", python=blocked),
             "--scheduler needs Dask's distributed package: pip install 'gimbaltrack[dask]'")


@pytest.mark.parametrize("address, text", [
    ("nope", "--scheduler 'nope' is not a Dask scheduler address (missing port number in address 'nope'; "
             "e.g. tcp://scheduler-host:8786)"),
    ("http://127.0.0.1:8786", "--scheduler 'http://127.0.0.1:8786' is not a Dask scheduler address (unknown address "
                              "scheme 'http'"),
])
def test_a_malformed_address_is_one_line(folders, address, text):
    captured = run("eval", str(folders[0]), "--scheduler", address)
    assert captured.returncode == 2 and len(captured.stderr.splitlines()) == 1
    assert captured.stderr.startswith(f"gimbaltrack eval: error: {text}"), captured.stderr


def test_no_scheduler_listening_is_one_line_after_dasks_connect_timeout(folders):
    port = free_udp_port()  # a TCP port nobody listens on, most likely
    env = {**subprocess_env(), "DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT": "1s"}
    one_line(run("eval", str(folders[0]), "--scheduler", f"tcp://127.0.0.1:{port}", env=env),
             f"no Dask scheduler answers at tcp://127.0.0.1:{port} (Timed out trying to connect to "
             f"tcp://127.0.0.1:{port} after 1 s)")
