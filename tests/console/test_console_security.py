"""Who may use the console: loopback without a token (Host checked), any other address with
one, and control requests only from the console's own origin."""
from __future__ import annotations

import json

import pytest

from pipelines.console import parse_console_address
from pipelines.console.address import ConsoleAddress
from pipelines.console.security import COOKIE
from tests.console.fakes import FrameFeeder, start_console
from tests.console.http_helpers import post, request


@pytest.mark.parametrize("text, address", [
    ("8080", ConsoleAddress("127.0.0.1", 8080)),
    ("0.0.0.0:8080", ConsoleAddress("0.0.0.0", 8080)),
    ("localhost:0", ConsoleAddress("localhost", 0)),
    ("[::1]:9000", ConsoleAddress("::1", 9000)),
])
def test_console_addresses(text: str, address: ConsoleAddress) -> None:
    assert parse_console_address(text) == address


@pytest.mark.parametrize("text, words", [("http", "port number"), ("host:", "port number"),
                                         (":80", "no host"), ("70000", "0 to 65535"), ("::1:80", "brackets")])
def test_bad_console_addresses_say_why(text: str, words: str) -> None:
    with pytest.raises(ValueError, match=words):
        parse_console_address(text)


@pytest.mark.parametrize("host, loopback", [("127.0.0.1", True), ("localhost", True), ("::1", True),
                                            ("127.0.0.2", True), ("0.0.0.0", False), ("192.168.1.5", False),
                                            ("myhost", False)])
def test_what_counts_as_loopback(host: str, loopback: bool) -> None:
    assert ConsoleAddress(host, 1).loopback is loopback


def test_loopback_needs_no_token_but_refuses_another_host_name() -> None:
    server, sink, operator = start_console()
    try:
        assert server.guard.token is None and "token" not in server.url
        assert request(server.port, "GET", "/api/state")[0] == 200
        status, _, body = request(server.port, "GET", "/api/state", headers={"Host": f"evil.example:{server.port}"})
        assert status == 403 and "loopback only" in json.loads(body)["error"]
        status, _reply = post(server.port, "/api/pause", {}, headers={"Host": "evil.example",
                                                                    "Origin": "http://evil.example"})
        assert status == 403 and operator.calls == []
    finally:
        server.stop()
        sink.close()


def test_another_address_needs_the_token_on_every_request() -> None:
    server, sink, operator = start_console(address="0.0.0.0:0")
    token = server.guard.token
    try:
        assert token and len(token) >= 20 and f"?token={token}" in server.url
        port = server.port
        for method, path in (("GET", "/"), ("GET", "/api/state"), ("GET", "/stream.mjpg"),
                             ("GET", "/api/events"), ("GET", "/console.js"), ("POST", "/api/pause")):
            status, _, body = request(port, method, path)
            assert status == 401 and "token" in json.loads(body)["error"], path
        assert request(port, "GET", "/api/state?token=wrong")[0] == 401
        assert request(port, "GET", "/api/state", headers={"Authorization": "Bearer wrong"})[0] == 401
        assert operator.calls == []
        status, headers, _ = request(port, "GET", f"/?token={token}")
        assert status == 200 and f"{COOKIE}={token}" in headers["Set-Cookie"]
        assert "HttpOnly" in headers["Set-Cookie"] and "SameSite=Strict" in headers["Set-Cookie"]
        assert request(port, "GET", "/api/state", headers={"Cookie": f"{COOKIE}={token}"})[0] == 200
        assert post(port, "/api/pause", {}, headers={"Authorization": f"Bearer {token}"}) == (200, {"ok": True})
        assert operator.calls == [("pause", None)]
    finally:
        server.stop()
        sink.close()


def test_a_token_given_is_required_on_loopback_too() -> None:
    server, sink, _operator = start_console(token="s3cret-token")
    try:
        assert server.url.endswith("/?token=s3cret-token")
        assert request(server.port, "GET", "/api/state")[0] == 401
        assert request(server.port, "GET", "/api/state?token=s3cret-token")[0] == 200
    finally:
        server.stop()
        sink.close()


def test_control_requests_from_another_origin_are_refused() -> None:
    server, sink, operator = start_console()
    port = server.port
    try:
        for origin in ("http://evil.example", "null", f"http://127.0.0.1:{port + 1}", f"https://127.0.0.1:{port}"):
            status, reply = post(port, "/api/record", {"on": True}, headers={"Origin": origin})
            assert status == 403 and "origin" in reply["error"], origin
        assert operator.calls == []
        assert post(port, "/api/record", {"on": True}, headers={"Origin": f"http://127.0.0.1:{port}"})[0] == 200
        assert post(port, "/api/record", {"on": False})[0] == 200  # no Origin: not a browser
        assert operator.calls == [("record", True), ("record", False)]
    finally:
        server.stop()
        sink.close()


def test_a_server_that_dies_stops_the_loop() -> None:
    from pipelines.console.sink import ConsoleFailed
    from tests.support import wait_until
    server, sink, _operator = start_console()
    with FrameFeeder(sink, fps=100) as feeder:
        assert wait_until(lambda: feeder.frames > 3, 5)
        server._loop.call_soon_threadsafe(server._main_task.cancel)
        assert wait_until(lambda: feeder.error is not None, 5)
    assert isinstance(feeder.error, ConsoleFailed) and "console stopped" in str(feeder.error)
    sink.close()


def test_stopping_the_server_leaves_the_loop_running() -> None:
    from tests.support import wait_until
    server, sink, _operator = start_console()
    with FrameFeeder(sink, fps=100) as feeder:
        server.stop()
        count = feeder.frames
        assert wait_until(lambda: feeder.frames > count + 5, 5) and feeder.error is None
    sink.close()
