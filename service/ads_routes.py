"""Which ADS peers are served, as a TwinCAT router decides it: by route.

A peer on the loopback interface is always served, from any AMS Net ID. Any other peer
needs a route whose address is the peer's IP address; it may then send from the Net IDs
of its routes only. A peer without a route is refused as soon as it connects.
"""

from __future__ import annotations

import ipaddress
from collections.abc import Iterable
from dataclasses import dataclass

from cnc_objects.protocol.ams import format_net_id, parse_net_id

IpAddress = ipaddress.IPv4Address | ipaddress.IPv6Address


@dataclass(frozen=True, slots=True)
class Route:
    """A configured route: a name, the peer's AMS Net ID and its IP address."""

    name: str
    net_id: bytes
    address: IpAddress

    @classmethod
    def parse(cls, name: str, net_id: str, address: str) -> Route:
        """A route from its configuration text; ``ValueError`` names what is wrong."""
        return cls(name, parse_net_id(net_id), ipaddress.ip_address(address))

    def __str__(self) -> str:
        return f"{self.name} ({format_net_id(self.net_id)} at {self.address})"


@dataclass(frozen=True, slots=True)
class Admission:
    """The decision for one peer: refused, or served from ``net_ids`` (None: any)."""

    allowed: bool
    net_ids: frozenset[bytes] | None = None

    def accepts(self, net_id: bytes) -> bool:
        """May this peer send frames from ``net_id``?"""
        return self.allowed and (self.net_ids is None or net_id in self.net_ids)


def peer_ip(host: str) -> IpAddress | None:
    """The IP address of a socket peer's host text (IPv4-mapped IPv6 as IPv4, zone
    dropped); None when it is not an IP address."""
    try:
        ip = ipaddress.ip_address(host.split("%", 1)[0])
    except ValueError:
        return None
    if isinstance(ip, ipaddress.IPv6Address) and ip.ipv4_mapped is not None:
        return ip.ipv4_mapped
    return ip


class RouteTable:
    """The routes of the configuration, and the admission of peers by them."""

    def __init__(self, routes: Iterable[Route] = ()) -> None:
        self.routes = tuple(routes)

    def __len__(self) -> int:
        return len(self.routes)

    def admit(self, host: str) -> Admission:
        """The decision for a peer connecting from ``host`` (its IP address as text)."""
        ip = peer_ip(host)
        if ip is None:
            return Admission(False)
        if ip.is_loopback:
            return Admission(True)
        net_ids = frozenset(r.net_id for r in self.routes if r.address == ip)
        return Admission(True, net_ids) if net_ids else Admission(False)
