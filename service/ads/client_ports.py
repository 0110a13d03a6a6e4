"""The AMS ports the service hands out as a router does: port registration (AMS/TCP
command 0x1000, ``protocol.ams_router``) for clients without an AMS address of their own.

A port is unique among live registrations. Without a wish, a client gets the lowest free
port from ``FIRST_CLIENT_PORT`` (32768) up: ports a client gave back are handed out
again, lowest first. A client may ask for a port of its own choice; it gets it when no
one holds it and it is not one of the ports the service serves (551 ... 10000). A
registration ends with its port close (0x0001) or when its connection closes. A
connection holds at most ``PORTS_PER_CONNECTION`` ports, so no one client can use up the
pool; a request that cannot be granted raises ``PortRefused`` saying why.
"""

from __future__ import annotations

import heapq
from collections.abc import Iterable

FIRST_CLIENT_PORT = 32768  # the range the ports of TwinCAT's clients are in (32905, ...)
LAST_CLIENT_PORT = 65535
PORTS_PER_CONNECTION = 64


class PortRefused(ValueError):
    """A port registration that cannot be granted; the message says why."""


class ClientPorts:
    """Live port registrations: which owner (a connection) holds which AMS port."""

    def __init__(self, reserved: Iterable[int] = (), first: int = FIRST_CLIENT_PORT,
                 last: int = LAST_CLIENT_PORT, per_owner: int = PORTS_PER_CONNECTION) -> None:
        """``reserved``: ports never handed out (the ones the service serves)."""
        self.reserved = frozenset(reserved)
        self.first, self.last, self.per_owner = first, last, per_owner
        self._owner_of: dict[int, object] = {}  # live port -> its owner
        self._ports_of: dict[object, set[int]] = {}  # owner -> its live ports
        self._next = first  # no port from here up has been handed out yet
        self._returned: list[int] = []  # heap of ports below _next given back

    def __len__(self) -> int:
        return len(self._owner_of)

    def held(self, owner: object) -> frozenset[int]:
        """The ports ``owner`` holds."""
        return frozenset(self._ports_of.get(owner, ()))

    def register(self, owner: object, wanted: int = 0) -> int:
        """A port for ``owner``: ``wanted`` (0: the lowest free one); ``PortRefused``."""
        mine = self._ports_of.get(owner, set())
        if len(mine) >= self.per_owner:
            raise PortRefused(f"this connection holds {len(mine)} ports already, the most "
                              "one connection may")
        port = self._free_port() if wanted == 0 else self._check(wanted)
        self._owner_of[port] = owner
        mine.add(port)
        self._ports_of[owner] = mine
        return port

    def release(self, owner: object, port: int) -> bool:
        """Give ``port`` back; False (nothing changes) when ``owner`` does not hold it."""
        if self._owner_of.get(port) is not owner:
            return False
        del self._owner_of[port]
        mine = self._ports_of[owner]
        mine.discard(port)
        if not mine:
            del self._ports_of[owner]
        if self.first <= port < self._next:
            heapq.heappush(self._returned, port)
        return True

    def release_all(self, owner: object) -> None:
        """Give back every port of ``owner`` (its connection closed)."""
        for port in list(self._ports_of.get(owner, ())):
            self.release(owner, port)

    def _check(self, wanted: int) -> int:
        if wanted in self.reserved:
            raise PortRefused(f"port {wanted} is one the service serves")
        if wanted in self._owner_of:
            raise PortRefused(f"port {wanted} is in use")
        return wanted

    def _free_port(self) -> int:
        returned = self._returned
        while returned:  # the lowest port given back, unless a client took it by wish
            port = heapq.heappop(returned)
            if port not in self._owner_of:
                return port
        while self._next <= self.last:
            port = self._next
            self._next += 1
            if port not in self._owner_of and port not in self.reserved:
                return port
        raise PortRefused(f"all {self.last - self.first + 1} client ports "
                          f"({self.first}..{self.last}) are in use")
