"""Who may use the console.

- On a loopback address the console is this machine's only; the ``Host`` header must name
  loopback, so a web page that rebinds its own name to 127.0.0.1 cannot reach it.
- On any other address every request needs the token: ``?token=`` (the page's printed URL; the
  page then gets it as a same-site cookie), the cookie, or ``Authorization: Bearer TOKEN``.
- Every control request (POST) that carries an ``Origin`` must come from the console's own
  origin: browsers send it with every POST, so another site's page cannot steer the gimbal.
"""
from __future__ import annotations

import hmac
import secrets
from urllib.parse import urlsplit

from aiohttp import web

from pipelines.console.address import LOOPBACK_NAMES, ConsoleAddress

COOKIE = "gimbaltrack_console"


def new_token() -> str:
    return secrets.token_urlsafe(18)


def _refused(status: int, reason: str) -> web.Response:
    return web.json_response({"error": reason}, status=status)


def _host_name(host_header: str) -> str:
    """``127.0.0.1:8080`` -> ``127.0.0.1``, ``[::1]:8080`` -> ``::1``."""
    return (urlsplit(f"//{host_header}").hostname or "").lower()


class Guard:
    """The checks above as one aiohttp middleware. ``token`` None on a non-loopback address
    makes one (printed with the URL)."""

    def __init__(self, address: ConsoleAddress, token: str | None = None) -> None:
        self.address = address
        self.token = token if token is not None or address.loopback else new_token()

    @web.middleware
    async def middleware(self, request: web.Request, handler) -> web.StreamResponse:
        host = request.headers.get("Host", "")
        if self.address.loopback and _host_name(host) not in LOOPBACK_NAMES | {self.address.host.lower()}:
            return _refused(403, f"this console answers on loopback only, not for Host {host!r}")
        if self.token is not None and not self._has_token(request):
            return _refused(401, "a token is required: open the URL printed at start (…/?token=…)")
        if request.method == "POST":
            origin = request.headers.get("Origin")
            if origin is not None and origin != f"{request.scheme}://{host}":
                return _refused(403, f"control requests from origin {origin!r} are refused")
        return await handler(request)

    def _has_token(self, request: web.Request) -> bool:
        given = [request.query.get("token"), request.cookies.get(COOKIE)]
        auth = request.headers.get("Authorization", "")
        if auth.startswith("Bearer "):
            given.append(auth[len("Bearer "):])
        return any(g is not None and hmac.compare_digest(g.encode(), self.token.encode()) for g in given)

    def remember(self, request: web.Request, response: web.StreamResponse) -> None:
        """The page was opened with the token in its URL: keep it as a cookie for the page's own
        requests (the live view, the status stream, the controls)."""
        if self.token is not None and request.query.get("token") is not None:
            response.set_cookie(COOKIE, self.token, httponly=True, samesite="Strict", path="/")
