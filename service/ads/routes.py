"""Which ADS peers are served, and with which role, as a TwinCAT router decides it: by route.

A peer on the loopback interface is always served, from any AMS Net ID, with the
loopback role (``[ads] loopback_role``: admin by default, monitor when the service runs
with ``--keys``). Any other peer needs a route whose address is the peer's IP address;
it may then send from the Net IDs of its routes only, each with its route's role
(``role`` of ``[[ads.routes]]``, operator by default). A peer without a route is refused
as soon as it connects, unless the table is open (``--insecure`` with no routes: every
peer is served as if on loopback).
"""

from __future__ import annotations

import ipaddress
from collections.abc import Iterable
from dataclasses import dataclass

from cnc_objects.protocol.ams import format_net_id, parse_net_id
from cnc_objects.protocol.roles import LOOPBACK_ROLE, Role

IpAddress = ipaddress.IPv4Address | ipaddress.IPv6Address


ROUTE_ROLE = Role.OPERATOR  # a route's role when its configuration names none


@dataclass(frozen=True, slots=True)
class Route:
    """A configured route: a name, the peer's AMS Net ID, its IP address and its role."""

    name: str
    net_id: bytes
    address: IpAddress
    role: Role = ROUTE_ROLE

    @classmethod
    def parse(cls, name: str, net_id: str, address: str, role: str | None = None) -> Route:
        """A route from its configuration text; ``ValueError`` names what is wrong."""
        return cls(name, parse_net_id(net_id), ipaddress.ip_address(address),
                   Role.parse(role) if role else ROUTE_ROLE)

    def __str__(self) -> str:
        return f"{self.name} ({format_net_id(self.net_id)} at {self.address}, {self.role.label})"


@dataclass(frozen=True, slots=True)
class Admission:
    """The decision for one peer: refused, or served with ``role`` from any Net ID
    (``roles`` None), or from the Net IDs of ``roles`` with each one's role."""

    allowed: bool
    roles: dict[bytes, Role] | None = None
    role: Role = Role.MONITOR

    def role_of(self, net_id: bytes) -> Role | None:
        """The role of frames from ``net_id``; None: this peer may not send from it."""
        if not self.allowed:
            return None
        if self.roles is None:
            return self.role
        return self.roles.get(net_id)

    def accepts(self, net_id: bytes) -> bool:
        """May this peer send frames from ``net_id``?"""
        return self.role_of(net_id) is not None


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

    def __init__(self, routes: Iterable[Route] = (), loopback_role: Role = LOOPBACK_ROLE,
                 open_to_all: bool = False) -> None:
        """``open_to_all``: serve peers without a route too, with the loopback role (the
        ``--insecure`` case of a service without routes on a non-loopback address)."""
        self.routes = tuple(routes)
        self.loopback_role = loopback_role
        self.open_to_all = open_to_all

    def __len__(self) -> int:
        return len(self.routes)

    def admit(self, host: str) -> Admission:
        """The decision for a peer connecting from ``host`` (its IP address as text)."""
        ip = peer_ip(host)
        if ip is None:
            return Admission(False)
        if ip.is_loopback or self.open_to_all:
            return Admission(True, None, self.loopback_role)
        # several routes of one address: the highest role of each Net ID
        roles: dict[bytes, Role] = {}
        for route in self.routes:
            if route.address == ip:
                roles[route.net_id] = max(route.role, roles.get(route.net_id, Role.MONITOR))
        return Admission(True, roles) if roles else Admission(False)
