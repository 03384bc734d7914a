"""ProgressReporter: a callable status is built only for a line that is drawn."""
from __future__ import annotations

import io

from pipelines.progress import ProgressReporter


def test_callable_status_is_called_only_when_drawn() -> None:
    stream = io.StringIO()
    reporter = ProgressReporter(10, stream=stream, interval=3600.0)
    calls: list[int] = []

    def status() -> str:
        calls.append(1)
        return "tracking"

    reporter.update(1, status, force=True)
    reporter.update(2, status)  # not due: an hour has not passed
    reporter.update(3, status, force=True)
    assert len(calls) == 2
    lines = stream.getvalue().splitlines()
    assert len(lines) == 2 and all(line.endswith("tracking") for line in lines)
    assert "1/10 frames" in lines[0] and "3/10 frames" in lines[1]


def test_the_first_line_waits_an_interval_so_its_rate_is_measured() -> None:
    stream = io.StringIO()
    reporter = ProgressReporter(10, stream=stream, interval=3600.0)
    reporter.update(1)
    assert stream.getvalue() == ""
