"""The ``gimbaltrack`` command. ``main`` is the console script; the parser and the run are in
``pipelines.cli.app``, which ``main`` imports with Ctrl-C and the terminating signals held, so that
one arriving while modules load is handled like any other (one line, no traceback, nothing lost).
Before the hold only ``pipelines.cli.process`` is imported, which needs nothing Python has not
loaded already, keeping that time as short as it can be; merely importing this package changes no
signal handling."""
from __future__ import annotations

from pipelines.cli.process import hold_signals, release_signals


def main(argv: list[str] | None = None) -> int:
    """Run ``gimbaltrack`` with ``argv`` (default: the command line); its exit status."""
    release = hold_signals()
    try:
        from pipelines.cli import app  # noqa: PLC0415 (imported here, under the hold)
    except BaseException:
        release_signals(release)
        raise
    return app.main(argv, release=release)
