"""The ``gimbaltrack`` command. ``main`` is the console script; the parser and the run are in
``pipelines.cli.app``, which ``main`` imports with Ctrl-C and the terminating signals held, so that
one arriving while modules load is handled like any other (one line, no traceback, nothing lost).
This module imports nothing but ``_signal`` (the C half of ``signal``, loaded with Python itself),
keeping the time before ``main`` holds them as short as it can be; merely importing it changes no
signal handling."""
from __future__ import annotations

import _signal

#: ``gimbal.signals``'s SIGINT and ``TERMINATING_SIGNALS``.
HELD_SIGNALS = tuple(getattr(_signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP", "SIGQUIT")
                     if hasattr(_signal, name))


def main(argv: list[str] | None = None) -> int:
    """Run ``gimbaltrack`` with ``argv`` (default: the command line); its exit status."""
    held = hasattr(_signal, "pthread_sigmask")
    release = _signal.pthread_sigmask(_signal.SIG_BLOCK, HELD_SIGNALS) if held else None
    try:
        from pipelines.cli import app  # noqa: PLC0415 (imported here, under the hold)
    except BaseException:
        if release is not None:
            _signal.pthread_sigmask(_signal.SIG_SETMASK, release)
        raise
    return app.main(argv, release=release)
