"""``gimbaltrack track --console``: the console serving one track run."""
from __future__ import annotations

import socket
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING

from pipelines.console.address import ConsoleAddress
from pipelines.console.loop_operator import LoopOperator, describe
from pipelines.console.server import ConsoleServer
from pipelines.console.sink import ConsoleSink

if TYPE_CHECKING:
    from pipelines.loop.track_session import TrackSession


@contextmanager
def serving(session: TrackSession, address: ConsoleAddress, sock: socket.socket,
            token: str | None) -> Iterator[ConsoleServer]:
    """Attach the console to ``session``'s loop and serve it on ``sock`` (bound to ``address``)
    until the block ends; the URL goes to stderr. The run's end (``finish``) happens inside the
    block, so the gimbal is stopped before the console closes."""
    operator = LoopOperator(session.loop, source_description=session.source.description,
                            frame_size=session.source.size, client=session.client, camera=session.camera)
    sink = ConsoleSink(describe, operator.dead_zone_px)
    session.loop.attach(operator)
    session.loop.attach(sink)
    server = ConsoleServer(operator, sink, address, token, sock=sock)
    try:
        server.start()
        print(f"gimbaltrack track: console at {server.url}", file=sys.stderr, flush=True)
        yield server
    finally:
        server.stop()
        sink.close()
