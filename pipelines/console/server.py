"""The console's HTTP server (aiohttp), on a thread of its own with its own event loop.

Pages and streams: ``GET /`` (the page), ``/stream.mjpg?fps=&width=`` (MJPEG, newest frame only;
each part carries ``X-Frame-Index`` and ``X-Capture-Time``, the frame's ``time.monotonic()``),
``/api/state`` (JSON) and ``/api/events`` (the same JSON pushed as server-sent events). Control:
``POST /api/select|pause|resume|recenter|record|stop|settings`` with JSON bodies
(``pipelines.console.bodies``). Security (``pipelines.console.security``): a token on any
address but loopback, the Host checked on loopback, the Origin on every control request.
"""
from __future__ import annotations

import asyncio
import json
import socket
import threading
from collections.abc import Awaitable, Callable
from importlib import resources
from typing import Any

from aiohttp import web

from pipelines.console.address import ConsoleAddress
from pipelines.console.bodies import (
    MAX_BODY_BYTES,
    RequestError,
    parse_empty,
    parse_record,
    parse_select,
    parse_settings,
)
from pipelines.console.operator import ConsoleOperator
from pipelines.console.security import Guard
from pipelines.console.sink import ConsoleSink, Snapshot
from pipelines.outputs._files import to_plain

MAX_VIEWERS = 4
MAX_EVENT_STREAMS = 8
DEFAULT_FPS = 15.0
DEFAULT_WIDTH = 960
FPS_RANGE = (0.5, 60.0)
WIDTH_RANGE = (64, 3840)
EVENTS_PERIOD_S = 0.2
SEND_BUFFER_BYTES = 64 * 1024
FLUSH_POLL_S = 0.005
STALL_S = 10.0  # a viewer that has not taken a frame in this long is dropped (its slot freed)
BOUNDARY = "frame"
STATIC = resources.files("pipelines.console") / "static"

Handler = Callable[[web.Request], Awaitable[web.StreamResponse]]


def error_response(status: int, reason: str) -> web.Response:
    """A 4xx/5xx with a one-line JSON reason."""
    return web.json_response({"error": reason.splitlines()[0] if reason else "error"}, status=status)


def _query_number(request: web.Request, name: str, default: float, low: float, high: float) -> float:
    text = request.query.get(name)
    if text is None:
        return default
    try:
        value = float(text)
    except ValueError:
        raise RequestError(400, f"{name} must be a number, not {text!r}") from None
    if not low <= value <= high:
        raise RequestError(422, f"{name} must be {low:g} to {high:g}, not {text}")
    return value


class ConsoleServer:
    """Serve the console for ``operator`` and ``sink`` on ``address``. ``start()`` returns once
    it listens (an OSError if it cannot); ``stop()`` closes it. A server that dies tells the sink,
    so the run stops the gimbal (``ConsoleFailed``)."""

    def __init__(self, operator: ConsoleOperator, sink: ConsoleSink, address: ConsoleAddress,
                 token: str | None = None, max_viewers: int = MAX_VIEWERS,
                 sock: socket.socket | None = None) -> None:
        self.operator = operator
        self.sock = sock  # already bound to ``address`` (``bind``), or None: bound at start
        self.sink = sink
        self.address = address
        self.guard = Guard(address, token)
        self.max_viewers = max_viewers
        self.viewers = 0
        self.event_streams = 0
        self.port: int | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._ready = threading.Event()
        self._start_error: BaseException | None = None
        self._closing: asyncio.Event | None = None
        self._new_frame: asyncio.Event | None = None
        self._main_task: asyncio.Task | None = None

    # -- lifetime ---------------------------------------------------------------------------
    @property
    def url(self) -> str:
        host = f"[{self.address.host}]" if ":" in self.address.host else self.address.host
        query = f"?token={self.guard.token}" if self.guard.token else ""
        return f"http://{host}:{self.port}/{query}"

    def start(self) -> str:
        self._thread = threading.Thread(target=self._serve, name="console-server", daemon=True)
        self._thread.start()
        self._ready.wait()
        if self._start_error is not None:
            raise OSError(f"cannot serve the console on {self.address.host}:{self.address.port}: "
                          f"{getattr(self._start_error, 'strerror', None) or self._start_error}")
        return self.url

    def stop(self) -> None:
        """Close every connection and the listening socket; the gimbal is not this server's concern."""
        loop, thread = self._loop, self._thread
        if loop is not None and thread is not None and thread.is_alive():
            try:
                loop.call_soon_threadsafe(self._closing.set)
            except RuntimeError:  # it closed meanwhile
                return
            thread.join(timeout=5.0)

    def _serve(self) -> None:
        loop = self._loop = asyncio.new_event_loop()
        try:
            self._main_task = loop.create_task(self._main())
            loop.run_until_complete(self._main_task)
        except BaseException as exc:  # noqa: BLE001 (a dying server must stop the run and the gimbal)
            if not self._ready.is_set():
                self._start_error = exc
            else:
                self.sink.fail(exc)
        finally:
            self._ready.set()
            loop.close()

    async def _main(self) -> None:
        self._closing = asyncio.Event()
        self._new_frame = asyncio.Event()
        runner = web.AppRunner(self.app(), access_log=None, handle_signals=False, shutdown_timeout=1.0)
        await runner.setup()
        try:
            site = (web.SockSite(runner, self.sock) if self.sock is not None
                    else web.TCPSite(runner, self.address.host, self.address.port))
            await site.start()
            self.port = runner.addresses[0][1]
            self._ready.set()
            await self._closing.wait()
        finally:
            await runner.cleanup()

    def app(self) -> web.Application:
        app = web.Application(middlewares=[self.guard.middleware], client_max_size=MAX_BODY_BYTES)
        app.add_routes([
            web.get("/", self._page),
            web.get("/console.js", self._static("console.js", "text/javascript")),
            web.get("/console.css", self._static("console.css", "text/css")),
            web.get("/stream.mjpg", self._stream),
            web.get("/api/state", self._state),
            web.get("/api/events", self._events),
            web.post("/api/select", self._control(self._select)),
            web.post("/api/pause", self._control(self._no_fields(self.operator.pause))),
            web.post("/api/resume", self._control(self._no_fields(self.operator.resume))),
            web.post("/api/recenter", self._control(self._no_fields(self.operator.recenter))),
            web.post("/api/stop", self._control(self._no_fields(self.operator.stop))),
            web.post("/api/record", self._control(lambda raw: self.operator.set_recording(parse_record(raw)))),
            web.post("/api/settings", self._control(self._settings)),
        ])
        return app

    # -- pages ------------------------------------------------------------------------------
    async def _page(self, request: web.Request) -> web.StreamResponse:
        response = web.Response(body=(STATIC / "index.html").read_bytes(), content_type="text/html")
        self.guard.remember(request, response)
        return response

    def _static(self, name: str, content_type: str) -> Handler:
        body = (STATIC / name).read_bytes()

        async def handler(request: web.Request) -> web.StreamResponse:
            return web.Response(body=body, content_type=content_type)
        return handler

    # -- status -----------------------------------------------------------------------------
    def state(self) -> dict[str, Any]:
        """The newest frame's view and the operator's status, JSON-ready."""
        snapshot = self.sink.latest()
        frame: dict[str, Any] = {"frame": None}
        if snapshot is not None:
            r = snapshot.view
            frame = {"frame": r.frame_index, "capture_t": r.capture_t, "state": r.state, "box": r.box,
                     "confidence": r.confidence, "rates_dps": r.rates_dps, "candidates": r.candidates}
        return to_plain({**frame, "frame_size": self.operator.frame_size(), **self.operator.state(),
                         "viewers": self.viewers})

    async def _state(self, request: web.Request) -> web.StreamResponse:
        return web.json_response(self.state(), dumps=_dumps)

    async def _events(self, request: web.Request) -> web.StreamResponse:
        if self.event_streams >= MAX_EVENT_STREAMS:
            return error_response(503, f"at most {MAX_EVENT_STREAMS} status streams at once")
        self.event_streams += 1
        try:
            response = web.StreamResponse(headers={"Content-Type": "text/event-stream",
                                                   "Cache-Control": "no-store"})
            await response.prepare(request)
            while not self._closing.is_set():
                data = f"data: {_dumps(self.state())}\n\n".encode()
                await asyncio.wait_for(response.write(data), STALL_S)
                await self._sleep_or_close(EVENTS_PERIOD_S)
            return response
        except (TimeoutError, ConnectionError):
            return web.Response(status=499)  # the viewer went away; nothing more to send
        finally:
            self.event_streams -= 1

    # -- the live view ----------------------------------------------------------------------
    async def _stream(self, request: web.Request) -> web.StreamResponse:
        try:
            fps = _query_number(request, "fps", DEFAULT_FPS, *FPS_RANGE)
            width = int(_query_number(request, "width", DEFAULT_WIDTH, *WIDTH_RANGE))
        except RequestError as exc:
            return error_response(exc.status, exc.reason)
        if self.viewers >= self.max_viewers:
            return error_response(503, f"at most {self.max_viewers} viewers at once; close another view first")
        self.viewers += 1
        try:
            response = web.StreamResponse(headers={
                "Content-Type": f"multipart/x-mixed-replace; boundary={BOUNDARY}",
                "Cache-Control": "no-store"})
            _small_send_buffer(request)
            await response.prepare(request)
            await self._send_frames(request, response, 1.0 / fps, width)
            return response
        except (TimeoutError, ConnectionError):
            return web.Response(status=499)
        finally:
            self.viewers -= 1

    async def _send_frames(self, request: web.Request, response: web.StreamResponse, period: float,
                           width: int) -> None:
        """Newest frame, at most once a ``period``; frames that come while a slow viewer is still
        reading the last one are skipped for it (a write that stalls ``STALL_S`` ends the view)."""
        loop = asyncio.get_running_loop()
        seq = 0
        while not self._closing.is_set():
            due = loop.time() + period
            snapshot = await self._next_frame(seq)
            if snapshot is None:
                return
            seq = snapshot.seq
            jpeg = await loop.run_in_executor(self.sink.executor, self.sink.encode, snapshot, width)
            head = (f"--{BOUNDARY}\r\nContent-Type: image/jpeg\r\nContent-Length: {len(jpeg)}\r\n"
                    f"X-Frame-Index: {snapshot.view.frame_index}\r\n"
                    f"X-Capture-Time: {snapshot.view.capture_t:.6f}\r\n\r\n").encode()
            await asyncio.wait_for(response.write(head + jpeg + b"\r\n"), STALL_S)
            await asyncio.wait_for(_flushed(request), STALL_S)
            await self._sleep_or_close(due - loop.time())

    async def _next_frame(self, after_seq: int) -> Snapshot | None:
        """The newest frame once it is newer than ``after_seq``; None when the server closes."""
        loop = asyncio.get_running_loop()
        while not self._closing.is_set():
            arrived = self._new_frame
            if self.sink.wake_on_next(lambda: loop.call_soon_threadsafe(self._frame_arrived), after_seq):
                closing = asyncio.ensure_future(self._closing.wait())
                waiting = asyncio.ensure_future(arrived.wait())
                await asyncio.wait({closing, waiting}, return_when=asyncio.FIRST_COMPLETED)
                closing.cancel()
                waiting.cancel()
                continue
            return self.sink.latest()
        return None

    def _frame_arrived(self) -> None:
        self._new_frame.set()
        self._new_frame = asyncio.Event()

    async def _sleep_or_close(self, seconds: float) -> None:
        if seconds > 0:
            try:
                await asyncio.wait_for(self._closing.wait(), seconds)
            except TimeoutError:
                pass

    # -- control ----------------------------------------------------------------------------
    def _control(self, act: Callable[[bytes], None]) -> Handler:
        """A control endpoint: read the body (at most ``MAX_BODY_BYTES``), check it, act."""
        async def handler(request: web.Request) -> web.StreamResponse:
            try:
                if request.content_length is not None and request.content_length > MAX_BODY_BYTES:
                    raise RequestError(413, f"the body is over {MAX_BODY_BYTES} bytes")
                try:
                    raw = await request.read()
                except web.HTTPRequestEntityTooLarge:
                    raise RequestError(413, f"the body is over {MAX_BODY_BYTES} bytes") from None
                if raw.strip() and request.content_type != "application/json":
                    raise RequestError(415, f"send JSON (Content-Type: application/json), not "
                                            f"{request.content_type}")
                act(raw)
            except RequestError as exc:
                return error_response(exc.status, exc.reason)
            except ValueError as exc:  # the operator refused a value (e.g. the controller's limits)
                return error_response(422, str(exc))
            return web.json_response({"ok": True})
        return handler

    @staticmethod
    def _no_fields(action: Callable[[], None]) -> Callable[[bytes], None]:
        def act(raw: bytes) -> None:
            parse_empty(raw)
            action()
        return act

    def _select(self, raw: bytes) -> None:
        self.operator.select(parse_select(raw, self.operator.frame_size()))

    def _settings(self, raw: bytes) -> None:
        self.operator.apply_settings(parse_settings(raw))


def _small_send_buffer(request: web.Request) -> None:
    """A send buffer of about one frame, so a slow viewer's backlog is short: it is shown a frame
    a little old, then the newest, never a queue of stale ones."""
    sock = request.transport.get_extra_info("socket") if request.transport is not None else None
    if sock is not None:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, SEND_BUFFER_BYTES)


async def _flushed(request: web.Request) -> None:
    """Until the last part has left this process for the kernel's send buffer."""
    transport = request.transport
    while transport is not None and not transport.is_closing() and transport.get_write_buffer_size():
        await asyncio.sleep(FLUSH_POLL_S)
    if transport is None or transport.is_closing():
        raise ConnectionResetError("the viewer went away")


def _dumps(value: Any) -> str:
    return json.dumps(value, separators=(",", ":"), allow_nan=False)
