"""The console's HTTP endpoints against a fake loop: pages, the live view, state, each control,
each bad input, and the limits on viewers."""
from __future__ import annotations

import itertools
import json
import time
from collections.abc import Iterator

import pytest

from pipelines.console.server import MAX_VIEWERS
from tests.console.fakes import SIZE, FrameFeeder, start_console
from tests.console.http_helpers import MjpegReader, decode_jpeg, post, request
from tests.support import wait_until


@pytest.fixture
def console() -> Iterator:
    server, sink, operator = start_console()
    with FrameFeeder(sink, fps=30) as feeder:
        assert wait_until(lambda: sink.latest() is not None, 5)
        yield server, sink, operator, feeder
    server.stop()
    sink.close()


def test_the_page_and_its_script_are_served(console) -> None:
    server = console[0]
    status, headers, body = request(server.port, "GET", "/")
    assert status == 200 and headers["Content-Type"].startswith("text/html")
    assert b'src="console.js"' in body
    status, headers, script = request(server.port, "GET", "/console.js")
    assert status == 200 and b"stream.mjpg" in script and b"api/events" in script


def test_state_carries_the_frame_and_the_run(console) -> None:
    status, _, body = request(console[0].port, "GET", "/api/state")
    state = json.loads(body)
    assert status == 200
    assert state["state"] == "tracking" and state["box"] == [100.0, 80.0, 40.0, 60.0]
    assert state["frame_size"] == list(SIZE) and state["candidates"] == [[300.0, 100.0, 50.0, 50.0]]
    for key in ("confidence", "rates_dps", "frame", "capture_t", "fps", "latency_ms", "bus", "recording",
                "source", "viewers"):
        assert key in state


def test_events_push_the_state_as_it_changes(console) -> None:
    import http.client
    connection = http.client.HTTPConnection("127.0.0.1", console[0].port, timeout=10)
    connection.request("GET", "/api/events")
    response = connection.getresponse()
    assert response.headers["Content-Type"] == "text/event-stream"
    frames = []
    while len(frames) < 3:
        line = response.readline()
        if line.startswith(b"data: "):
            frames.append(json.loads(line[6:])["frame"])
    connection.close()
    assert frames[0] < frames[1] < frames[2]


def test_the_view_is_the_newest_frame_at_the_asked_width_and_rate(console) -> None:
    server = console[0]
    reader = MjpegReader(server.port, "?fps=5&width=320")
    assert reader.status == 200 and reader.response.headers["Content-Type"].startswith("multipart/x-mixed-replace")
    started = time.monotonic()
    parts = [reader.part() for _ in range(6)]
    elapsed = time.monotonic() - started
    reader.close()
    indexes = [int(h["x-frame-index"]) for h, _ in parts]
    assert indexes == sorted(indexes) and len(set(indexes)) == 6
    assert elapsed >= 0.8  # five gaps at 5 fps
    images = [decode_jpeg(data) for _, data in parts]
    assert images[0].shape == (180, 320, 3)
    assert any(abs(a.astype(int) - b.astype(int)).mean() > 1 for a, b in itertools.pairwise(images))
    default = MjpegReader(server.port)
    assert decode_jpeg(default.part()[1]).shape[1] == SIZE[0]  # 960 by default: a 640 frame is not grown
    default.close()


@pytest.mark.parametrize("query, status", [("?fps=0", 422), ("?fps=abc", 400), ("?width=10", 422),
                                           ("?width=99999", 422)])
def test_bad_view_parameters_are_refused(console, query: str, status: int) -> None:
    got, _, body = request(console[0].port, "GET", f"/stream.mjpg{query}")
    assert got == status and "\n" not in json.loads(body)["error"]


@pytest.mark.parametrize("path, payload, call", [
    ("/api/select", {"box": [10, 20, 30, 40]}, ("select", (10.0, 20.0, 30.0, 40.0))),
    ("/api/pause", None, ("pause", None)),
    ("/api/pause", {}, ("pause", None)),
    ("/api/resume", None, ("resume", None)),
    ("/api/recenter", None, ("recenter", None)),
    ("/api/record", {"on": True}, ("record", True)),
    ("/api/record", {"on": False}, ("record", False)),
    ("/api/stop", None, ("stop", None)),
    ("/api/settings", {"max_speed": 90, "dead_zone": 0.2}, ("settings", {"max_speed": 90.0, "dead_zone": 0.2})),
    ("/api/settings", {"kp": 8, "ki": 0.5, "kd": 0.1}, ("settings", {"kp": 8.0, "ki": 0.5, "kd": 0.1})),
])
def test_each_control_reaches_the_operator(console, path, payload, call) -> None:
    status, reply = post(console[0].port, path, payload)
    assert (status, reply) == (200, {"ok": True})
    assert console[2].calls == [call]


@pytest.mark.parametrize("path, body, status, words", [
    ("/api/select", "{not json", 400, "not valid JSON"),
    ("/api/select", "[1, 2]", 400, "JSON object"),
    ("/api/select", '{"box": [1, 2, 3, 4], "extra": 1}', 400, "unknown field 'extra'"),
    ("/api/select", '{"box": [1, 2, 3]}', 400, "four numbers"),
    ("/api/select", '{"box": [1, 2, "3", 4]}', 400, "box[2] must be a number"),
    ("/api/select", '{"box": [1, 2, true, 4]}', 400, "box[2] must be a number"),
    ("/api/select", '{"box": [1, 2, NaN, 4]}', 400, "not valid JSON"),
    ("/api/select", '{"box": [700, 10, 40, 40]}', 422, "outside the 640x360 frame"),
    ("/api/select", '{"box": [620, 10, 60, 40]}', 422, "mostly outside"),
    ("/api/select", '{"box": [10, 10, 0, 40]}', 422, "at least 2 x 2"),
    ("/api/select", '{"box": [10, 10, -5, 40]}', 422, "at least 2 x 2"),
    ("/api/select", "{}", 400, "four numbers"),
    ("/api/record", '{"on": "yes"}', 400, "true"),
    ("/api/record", '{"on": 1}', 400, "true"),
    ("/api/record", "{}", 400, "true"),
    ("/api/pause", '{"now": true}', 400, "unknown field 'now' (this request takes no fields)"),
    ("/api/stop", '"stop"', 400, "JSON object"),
    ("/api/settings", "{}", 400, "one or more of"),
    ("/api/settings", '{"max_speed": 400}', 422, "max_speed must be 1 to 360"),
    ("/api/settings", '{"max_speed": 0}', 422, "max_speed must be 1 to 360"),
    ("/api/settings", '{"kp": -1}', 422, "kp must be 0 to 100"),
    ("/api/settings", '{"dead_zone": 1e400}', 422, "finite"),
    ("/api/settings", '{"gain": 3}', 400, "unknown field 'gain'"),
    ("/api/settings", '{"kp": 2, "ki": "x"}', 400, "ki must be a number"),
])
def test_bad_control_bodies_get_a_4xx_reason_and_change_nothing(console, path, body, status, words) -> None:
    got, _, data = request(console[0].port, "POST", path, body)
    reason = json.loads(data)["error"]
    assert got == status, reason
    assert words in reason and "\n" not in reason
    assert console[2].calls == []


def test_an_oversized_body_is_refused(console) -> None:
    port = console[0].port
    got, _, data = request(port, "POST", "/api/select", '{"box": [1, 2, 3, 4]}' + " " * 5000)
    assert got == 413 and "4096 bytes" in json.loads(data)["error"]
    import http.client
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=10)  # no length given: chunked
    connection.request("POST", "/api/pause", body=iter([b"{}", b" " * 5000]),
                       headers={"Content-Type": "application/json"})
    response = connection.getresponse()
    assert response.status == 413 and "4096 bytes" in json.loads(response.read())["error"]
    connection.close()
    assert console[2].calls == []


def test_a_body_that_is_not_json_by_its_type_is_refused(console) -> None:
    got, _, data = request(console[0].port, "POST", "/api/record", '{"on": true}',
                           headers={"Content-Type": "text/plain"})
    assert got == 415 and "application/json" in json.loads(data)["error"]
    assert console[2].calls == []


def test_a_value_the_operator_refuses_is_a_422_with_its_reason() -> None:
    server, sink, operator = start_console()
    operator.refuse_settings = "the stop ramp from max_speed_dps over ramp_s would exceed max_accel_dps2"
    try:
        status, reply = post(server.port, "/api/settings", {"max_speed": 300})
    finally:
        server.stop()
        sink.close()
    assert status == 422 and reply["error"] == operator.refuse_settings


def test_select_before_the_first_frame_is_refused() -> None:
    server, sink, operator = start_console()
    operator.frame_size = lambda: None
    try:
        status, reply = post(server.port, "/api/select", {"box": [1, 2, 30, 40]})
    finally:
        server.stop()
        sink.close()
    assert status == 409 and "no frame" in reply["error"] and operator.calls == []


def test_four_viewers_at_once_and_a_fifth_is_told_why(console) -> None:
    server = console[0]
    readers = [MjpegReader(server.port, "?fps=30&width=160") for _ in range(MAX_VIEWERS)]
    try:
        for reader in readers:
            assert reader.status == 200
            reader.part()
        status, _, body = request(server.port, "GET", "/stream.mjpg")
        assert status == 503 and "at most 4 viewers" in json.loads(body)["error"]
        readers.pop().close()
        assert wait_until(lambda: server.viewers < MAX_VIEWERS, 5)
        again = MjpegReader(server.port, "?width=160")
        readers.append(again)
        assert again.status == 200 and again.part()[1]
        for reader in readers:  # all four still get new frames
            first = int(reader.part()[0]["x-frame-index"])
            assert int(reader.part()[0]["x-frame-index"]) > first
    finally:
        for reader in readers:
            reader.close()
