"""``--console [HOST:]PORT``: where the console listens, and whether that needs a token."""
from __future__ import annotations

import ipaddress
import socket
from dataclasses import dataclass

DEFAULT_HOST = "127.0.0.1"
LOOPBACK_NAMES = frozenset({"localhost", "127.0.0.1", "::1"})


@dataclass(frozen=True)
class ConsoleAddress:
    host: str
    port: int  # 0: a free port chosen by the system

    @property
    def loopback(self) -> bool:
        """Only this machine can connect: no token is needed (unless one is given)."""
        if self.host in LOOPBACK_NAMES:
            return True
        try:
            return ipaddress.ip_address(self.host).is_loopback
        except ValueError:  # a host name other than localhost may resolve anywhere
            return False


def parse_console_address(text: str) -> ConsoleAddress:
    """``PORT``, ``HOST:PORT`` or ``[IPv6]:PORT``; ValueError with the reason otherwise."""
    host, sep, port_text = text.strip().rpartition(":")
    if not sep:
        host = DEFAULT_HOST
    elif host.startswith("[") and host.endswith("]"):
        host = host[1:-1]
    if sep and not host:
        raise ValueError(f"--console takes [HOST:]PORT, not {text!r} (no host before the colon)")
    if ":" in host and not text.strip().startswith("["):
        raise ValueError(f"--console takes an IPv6 host in brackets, e.g. [::1]:8080, not {text!r}")
    try:
        port = int(port_text)
    except ValueError:
        raise ValueError(f"--console takes [HOST:]PORT with a port number, not {text!r}") from None
    if not 0 <= port <= 65535:
        raise ValueError(f"--console port must be 0 to 65535 (0: any free port), not {port}")
    return ConsoleAddress(host, port)


def bind(address: ConsoleAddress) -> socket.socket:
    """A listening socket on ``address`` (so a port in use is found before a run starts);
    OSError with the system's reason otherwise."""
    infos = socket.getaddrinfo(address.host, address.port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    family, kind, proto, _, where = infos[0]
    sock = socket.socket(family, kind, proto)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind(where)
        sock.listen(64)
    except OSError:
        sock.close()
        raise
    return sock
