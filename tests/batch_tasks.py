"""Tasks for ``pipelines.batch`` tests: module-level, so that worker processes can load them."""
from __future__ import annotations

import os
import time

from pipelines.batch import InputFailed


def late_square(value: int) -> tuple[int, int]:
    """``value`` squared, later the smaller ``value`` is (the first inputs finish last), with the
    id of the process that did it."""
    time.sleep(0.3 * (3 - value) if value < 3 else 0)
    return value * value, os.getpid()


def fails_on_odd(value: int) -> int:
    """Worded failure on 1, a bug (ZeroDivisionError) on 3, ``value`` otherwise."""
    if value == 1:
        raise InputFailed("one: cannot do it")
    if value == 3:
        return value // 0
    return value


def thread_variables(_: object) -> dict[str, str | None]:
    """What a worker's one-thread settings are."""
    import cv2

    return {"cv2": str(cv2.getNumThreads()), **{name: os.environ.get(name) for name in
                                                 ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}}
