"""Plain HTTP against a console on 127.0.0.1, with the headers a test chooses."""
from __future__ import annotations

import http.client
import json
import socket
from typing import Any

import cv2
import numpy as np


def request(port: int, method: str, path: str, body: bytes | str | None = None,
            headers: dict[str, str] | None = None) -> tuple[int, http.client.HTTPMessage, bytes]:
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    try:
        if isinstance(body, str):
            body = body.encode()
        all_headers = {"Content-Type": "application/json"} if body else {}
        all_headers.update(headers or {})
        connection.request(method, path, body=body, headers=all_headers)
        response = connection.getresponse()
        return response.status, response.headers, response.read()
    finally:
        connection.close()


def post(port: int, path: str, payload: Any = None, **kwargs: Any) -> tuple[int, dict[str, Any]]:
    body = None if payload is None else json.dumps(payload)
    status, _, data = request(port, "POST", path, body, **kwargs)
    return status, json.loads(data)


class MjpegReader:
    """Reads an MJPEG stream part by part: (headers, JPEG bytes)."""

    def __init__(self, port: int, query: str = "", headers: dict[str, str] | None = None,
                 receive_buffer: int | None = None) -> None:
        self.connection = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
        if receive_buffer is not None:  # a slow link: little in flight
            self.connection.connect()
            self.connection.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, receive_buffer)
        self.connection.request("GET", f"/stream.mjpg{query}", headers=headers or {})
        self.response = self.connection.getresponse()
        self.status = self.response.status

    def part(self) -> tuple[dict[str, str], bytes]:
        """The next part; EOFError once the server has ended the stream."""
        line = self.response.readline()
        while line in (b"\r\n", b"\n"):
            line = self.response.readline()
        if not line:
            raise EOFError("the stream ended")
        assert line.strip() == b"--frame", line
        headers = {}
        while (line := self.response.readline().strip()):
            name, _, value = line.decode().partition(":")
            headers[name.strip().lower()] = value.strip()
        data = self.response.read(int(headers["content-length"]))
        return headers, data

    def close(self) -> None:
        self.connection.close()


def decode_jpeg(data: bytes) -> np.ndarray:
    image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
    assert image is not None, "not a JPEG"
    return image


def stalled_viewer(port: int) -> socket.socket:
    """A viewer that asks for the stream and never reads it (a tiny receive buffer)."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    sock.connect(("127.0.0.1", port))
    sock.sendall(f"GET /stream.mjpg?fps=60&width=640 HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n".encode())
    return sock
