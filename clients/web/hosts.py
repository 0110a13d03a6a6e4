"""Requests must name this server: the Host and Origin checks against DNS rebinding.

A page of another site whose name an attacker points at this machine's address (DNS
rebinding) makes the browser send requests that the same-origin rule no longer stops:
they come with ``Host: evil.example:8080``. So every request's ``Host`` must be one of
this server's names with the port the request came in on, and a request that carries an
``Origin`` (browsers send it with writes, uploads and WebSockets) must come from such an
address too:

- the names: ``localhost``, ``127.0.0.1``, ``::1``, the address cnc-web serves on
  (``--host``), the address the connection came in on (the machine's own address, as a
  browser writes it when it is typed), and each ``--allow-host NAME``;
- the port: the one the connection came in on (80 when ``Host`` names none).

Anything else is refused before any other check: 421 for a foreign ``Host``, 403 for a
foreign ``Origin``, with a JSON ``error`` that says which names are served.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from urllib.parse import urlsplit

from aiohttp import web

from .access import Handler, refusal

LOOPBACK_NAMES = ("localhost", "127.0.0.1", "::1")
DEFAULT_PORTS = {"http": 80, "https": 443}

HOSTS_KEY: web.AppKey[AllowedHosts] = web.AppKey("hosts")


@dataclass(frozen=True)
class AllowedHosts:
    """The host names (lowercase, IPv6 without brackets) requests may address."""

    names: frozenset[str]

    @classmethod
    def serving(cls, host: str, extra: Iterable[str] = ()) -> AllowedHosts:
        """The names of a server bound to ``host``, with ``extra`` (``--allow-host``)."""
        names = {*LOOPBACK_NAMES, host.strip("[]").lower(), *(n.strip("[]").lower() for n in extra)}
        return cls(frozenset(names - {"", "0.0.0.0", "::"}))

    def check(self, request: web.Request) -> None:
        """Nothing when ``request`` addresses this server; else the refusal is raised."""
        local = request.transport.get_extra_info("sockname") if request.transport else None
        if not local:
            raise refusal(421, "the connection is closed")
        local_address, local_port = str(local[0]).lower(), int(local[1])
        served = self.names | {local_address}
        host = request.headers.get("Host", "")
        if not _addresses(f"http://{host}", served, local_port):
            raise refusal(421, f"Host {host!r} is not this server: it serves "
                               f"{self._described(served, local_port)} (more names: --allow-host)")
        origin = request.headers.get("Origin")
        if origin is not None and not _addresses(origin, served, local_port):
            raise refusal(403, f"Origin {origin!r} is not this server: requests are taken from "
                               f"pages of {self._described(served, local_port)} only")

    @staticmethod
    def _described(served: frozenset[str], port: int) -> str:
        return ", ".join(f"{f'[{n}]' if ':' in n else n}:{port}" for n in sorted(served))


def _addresses(url: str, served: frozenset[str], port: int) -> bool:
    """True when ``url`` (``scheme://host[:port]``) names one of ``served`` at ``port``."""
    try:
        parts = urlsplit(url)
        named_port = parts.port or DEFAULT_PORTS.get(parts.scheme)
    except ValueError:  # a port that is not a number, a broken IPv6 literal
        return False
    return (parts.scheme in DEFAULT_PORTS and parts.hostname in served and named_port == port
            and not parts.path and not parts.query and parts.username is None)


@web.middleware
async def host_middleware(request: web.Request, handler: Handler) -> web.StreamResponse:
    """Refuse a request that does not address this server (see the module docstring)."""
    request.app[HOSTS_KEY].check(request)
    return await handler(request)
