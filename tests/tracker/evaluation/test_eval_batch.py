"""``gimbaltrack eval --jobs N``: the same boxes and scores as one after the other, rows in input
order, a failing sequence named, one-line option errors, Ctrl-C keeps what finished."""
from __future__ import annotations

import json
import signal
import subprocess
import time
from pathlib import Path

import pytest

from pipelines.cli.eval_cmd import score_all
from tests import fake_onnx
from tests.support import cli_command, signalled
from tests.tracker.evaluation.batch_helpers import long_sequence, scores, write_otb
from tracker.evaluation.datasets import load_sequence


def gimbaltrack(*argv: str) -> subprocess.CompletedProcess:
    return subprocess.run(cli_command(*argv), capture_output=True, text=True, timeout=180)


@pytest.fixture(scope="module")
def folders(tmp_path_factory) -> list[Path]:
    root = tmp_path_factory.mktemp("batch")
    return [write_otb(root / f"seq{seed}", frames, seed) for seed, frames in ((3, 40), (5, 25), (7, 50))]


@pytest.mark.parametrize("tracker", ["default", "kcf"])
def test_two_jobs_give_the_boxes_and_scores_of_one(folders, tracker):
    sequences = [load_sequence(f) for f in folders]
    serial = score_all(sequences, tracker, jobs=1)
    parallel = score_all(sequences, tracker, jobs=2)
    assert all(o.error is None for o in serial + parallel)
    assert scores(parallel) == scores(serial)
    assert len(serial[0].result.boxes) == 40 and serial[0].result.boxes[5] != serial[0].result.boxes[6]


def rows(captured: subprocess.CompletedProcess) -> list[dict]:
    """The JSON rows without their timings."""
    return [{k: v for k, v in json.loads(line).items() if "fps" not in k} for line in captured.stdout.splitlines()]


def test_the_command_prints_the_same_rows_in_the_same_order(folders):
    args = [str(folders[2]), str(folders[0]), str(folders[1]), "--json"]
    serial, parallel, clamped = (gimbaltrack("eval", *args, *jobs) for jobs in ([], ["--jobs", "2"], ["--jobs", "9"]))
    assert serial.returncode == parallel.returncode == clamped.returncode == 0, parallel.stderr
    assert rows(parallel) == rows(serial) == rows(clamped)
    assert [r.get("sequence") for r in rows(parallel)] == ["seq7", "seq3", "seq5", None]
    assert "115/115 frames" in parallel.stderr and "3/3 sequences" in parallel.stderr  # one line for the batch


def test_an_unreadable_frame_is_named_and_the_others_are_scored(folders, tmp_path):
    broken = write_otb(tmp_path / "broken", frames=6, seed=3)
    (broken / "img" / "0004.png").write_bytes(b"not a png")
    captured = gimbaltrack("eval", str(folders[0]), str(broken), str(folders[1]), "--json", "--jobs", "2")
    assert captured.returncode == 2
    assert [r.get("sequence") for r in rows(captured)] == ["seq3", "seq5", None] and rows(captured)[-1]["sequences"] == 2
    errors = [line for line in captured.stderr.splitlines() if "error" in line]
    assert errors == [f"gimbaltrack eval: error: broken: cannot read frame 4 ({broken / 'img' / '0004.png'}) "
                      "(skipped; the summary covers the other sequences)"]


@pytest.mark.parametrize("argv, message", [
    (["--jobs", "0"], "--jobs takes 1 or more worker processes, not 0"),
    (["--jobs", "-3"], "--jobs takes 1 or more worker processes, not -3"),
    (["--jobs", "2", "--scheduler", "tcp://127.0.0.1:8786"],
     "--jobs runs on this machine, --scheduler on a Dask cluster: give one of them"),
    (["--scheduler", " "], "--scheduler takes the address of a Dask scheduler, e.g. tcp://scheduler-host:8786"),
])
def test_bad_jobs_are_one_line(folders, argv, message):
    captured = gimbaltrack("eval", str(folders[0]), *argv)
    assert captured.returncode == 2 and captured.stdout == ""
    assert captured.stderr.splitlines() == [f"gimbaltrack eval: error: {message}"]


def test_jobs_that_is_no_number_is_refused_by_the_parser(folders):
    captured = gimbaltrack("eval", str(folders[0]), "--jobs", "two")
    assert captured.returncode == 2 and "argument --jobs: not a whole number: 'two'" in captured.stderr


def test_the_summary_names_the_tracker_and_its_model(folders, tmp_path):
    plain = gimbaltrack("eval", str(folders[1]), "--tracker", "dcf", "--json")
    assert json.loads(plain.stdout.splitlines()[-1])["tracker"] == "dcf"
    assert json.loads(plain.stdout.splitlines()[-1])["model"] is None
    models = fake_onnx.write_nanotrack_files(tmp_path / "models", fake_onnx.backbone_bytes(), fake_onnx.head_bytes())
    nano = gimbaltrack("eval", str(folders[1]), "--tracker", "nanotrack", "--model-dir", str(models), "--json",
                       "--jobs", "2")
    summary = json.loads(nano.stdout.splitlines()[-1])
    assert summary["tracker"] == "nanotrack" and summary["model"] == str(models)


def finished_one(process: subprocess.Popen) -> bool:
    """Wait for the progress line saying that one sequence is done."""
    return any("1/3 sequences" in line for line in iter(process.stderr.readline, ""))


@pytest.mark.parametrize("signum, code, last", [(signal.SIGINT, 130, "interrupted"),
                                                 (signal.SIGTERM, 143, "terminated (SIGTERM)")])
def test_a_stop_ends_the_workers_and_prints_what_finished(folders, tmp_path, signum, code, last):
    """The short sequence finishes second in line while the first still runs: its row is printed
    on the way out, the long ones are not waited for, and nothing is a traceback."""
    slow = long_sequence(tmp_path / "slow")
    command = cli_command("eval", str(slow), str(folders[1]), str(slow), "--tracker", "csrt", "--jobs", "2", "--json")
    started = time.monotonic()
    status, stdout, stderr = signalled(command, finished_one, signum=signum)
    assert time.monotonic() - started < 60  # csrt on 3000 frames, twice, takes minutes here
    assert status == code and "Traceback" not in stderr
    assert [json.loads(line)["sequence"] for line in stdout.splitlines()] == ["seq5"]  # no summary
    assert stderr.splitlines()[-1] == f"gimbaltrack eval: {last}"


def test_two_jobs_give_the_boxes_of_one_on_real_footage(shared_data):
    """Two shared sequences of different sizes (640 x 360 and 1280 x 720), box by box."""
    sequences = [load_sequence(shared_data / "sequences" / name) for name in ("otb_skiing", "uav123_car14")]
    serial, parallel = score_all(sequences, jobs=1), score_all(sequences, jobs=2)
    assert all(o.error is None for o in serial + parallel) and scores(parallel) == scores(serial)


def test_workers_end_when_the_command_is_killed(folders, tmp_path):
    """A SIGKILL gives the command no chance to stop its workers: they notice it has gone and end
    within seconds instead of running (or waiting to hand back a result) for ever."""
    slow = long_sequence(tmp_path / "slow")
    command = cli_command("eval", str(slow), str(slow), "--tracker", "csrt", "--jobs", "2", "--json")
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        workers: list[int] = []
        deadline = time.monotonic() + 60
        while len(workers) < 2 and time.monotonic() < deadline:
            time.sleep(0.2)
            workers = [pid for pid in _children(process.pid) if _is_worker(pid)]
        assert len(workers) == 2, "the workers never started"
        time.sleep(2)  # both under way on their sequence
        process.kill()
        process.wait()
        deadline = time.monotonic() + 10
        while any(_running(pid) for pid in workers) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert not any(_running(pid) for pid in workers)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
        process.stdout.close()
        process.stderr.close()


def _children(pid: int) -> list[int]:
    return [int(p) for p in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]


def _is_worker(pid: int) -> bool:
    try:
        return "spawn_main" in Path(f"/proc/{pid}/cmdline").read_text()
    except OSError:
        return False


def _running(pid: int) -> bool:
    """Alive and not a zombie waiting to be reaped."""
    try:
        status = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return status.rsplit(")", 1)[1].split()[0] != "Z"
