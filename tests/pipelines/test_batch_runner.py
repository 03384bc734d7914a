"""``pipelines.batch.run_batch``: input order, failures by name, one thread per worker."""
from __future__ import annotations

import os

import pytest

from pipelines.batch import Outcome, run_batch
from tests import batch_tasks


def names(values: list[int]) -> list[tuple[str, int]]:
    return [(f"in{v}", v) for v in values]


def test_outcomes_come_in_input_order_whatever_finishes_first():
    shown: list[Outcome] = []
    arrived: list[int] = []
    outcomes = run_batch(batch_tasks.late_square, names([0, 1, 2, 3]), jobs=2, show=shown.append,
                         finished=lambda outcome: arrived.append(outcome.index))
    assert [o.index for o in shown] == [0, 1, 2, 3] == [o.index for o in outcomes]
    assert [o.result[0] for o in outcomes] == [0, 1, 4, 9] and [o.name for o in outcomes] == ["in0", "in1", "in2", "in3"]
    assert arrived != [0, 1, 2, 3]  # input 0 sleeps longest: the order above is the runner's doing
    workers = {o.result[1] for o in outcomes}
    assert len(workers) == 2 and os.getpid() not in workers


def test_one_job_runs_here_in_order():
    outcomes = run_batch(batch_tasks.late_square, names([2, 3]), show=lambda outcome: None)
    assert [o.result for o in outcomes] == [(4, os.getpid()), (9, os.getpid())]


@pytest.mark.parametrize("jobs", [1, 2])
def test_a_failing_input_is_named_and_the_others_finish(jobs):
    outcomes = run_batch(batch_tasks.fails_on_odd, names([0, 1, 2, 3, 4]), jobs=jobs, show=lambda outcome: None)
    assert [o.result for o in outcomes] == [0, None, 2, None, 4]
    assert outcomes[1].error == "one: cannot do it" and outcomes[1].detail is None
    assert outcomes[3].error == "in3: ZeroDivisionError: integer division or modulo by zero"
    assert "Traceback" in outcomes[3].detail and "fails_on_odd" in outcomes[3].detail


def test_workers_run_one_thread_each(monkeypatch):
    monkeypatch.setenv("OMP_NUM_THREADS", "8")
    outcomes = run_batch(batch_tasks.thread_variables, names([0, 1]), jobs=2, show=lambda outcome: None)
    assert all(o.result == {"cv2": "1", "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
               for o in outcomes)
    assert os.environ["OMP_NUM_THREADS"] == "8"  # this process's own setting is put back
