"""ProgressReporter: a callable status is built only for a line that is drawn."""
from __future__ import annotations

import io
from types import SimpleNamespace

import pytest

import pipelines.outputs.progress
from pipelines.outputs.progress import ProgressReporter


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


# ProgressReporter: lines at most an interval apart (2 s when not a terminal), the bar never past
# 100 % (a file's header may under-count its frames), and a closing newline only on a terminal.
class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.fixture
def clock(monkeypatch: pytest.MonkeyPatch) -> list[float]:
    """The reporter's clock: set ``clock[0]`` to move it."""
    now = [100.0]
    monkeypatch.setattr(pipelines.outputs.progress, "time", SimpleNamespace(monotonic=lambda: now[0]))
    return now


def test_lines_are_an_interval_apart_from_the_last_one_drawn(clock: list[float]) -> None:
    stream = io.StringIO()  # not a terminal: every 2 s at most
    reporter = ProgressReporter(None, stream=stream, interval=0.25)
    for t, done in [(102.5, 1), (103.0, 2), (104.4, 3), (104.6, 4)]:
        clock[0] = t
        reporter.update(done)
    assert [line.split()[0] for line in stream.getvalue().splitlines()] == ["1", "4"]
    reporter.close()
    assert stream.getvalue().count("\n") == 2  # no extra newline off a terminal


def test_the_bar_stops_at_100_percent_and_a_terminal_gets_its_newline(clock: list[float]) -> None:
    stream = _Terminal()
    reporter = ProgressReporter(10, stream=stream)
    reporter.update(15, "tracking", force=True)
    assert stream.getvalue().startswith(f"\r[{'#' * 24}] 100% 15/10 frames")
    reporter.close()
    assert stream.getvalue().endswith("\n") and stream.getvalue().count("\n") == 1
