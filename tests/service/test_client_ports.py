"""The AMS ports handed out by port registration (service/ads/client_ports.py): unique
among live registrations, the lowest free one first, freed ports handed out again, a
wish granted when free, and every refusal saying why."""

from __future__ import annotations

import pytest

from cnc_objects.service.ads.client_ports import FIRST_CLIENT_PORT, ClientPorts, PortRefused


def test_ports_from_32768_unique_and_the_lowest_free_first() -> None:
    ports = ClientPorts()
    a, b = object(), object()
    assert [ports.register(a), ports.register(b), ports.register(a)] == [
        FIRST_CLIENT_PORT, FIRST_CLIENT_PORT + 1, FIRST_CLIENT_PORT + 2]
    assert ports.held(a) == {FIRST_CLIENT_PORT, FIRST_CLIENT_PORT + 2}
    assert ports.release(a, FIRST_CLIENT_PORT + 2) and ports.release(a, FIRST_CLIENT_PORT)
    assert not ports.release(a, FIRST_CLIENT_PORT + 1)  # b's: nothing changes
    assert ports.register(b) == FIRST_CLIENT_PORT  # given back: handed out again
    assert ports.register(b) == FIRST_CLIENT_PORT + 2
    assert ports.register(b) == FIRST_CLIENT_PORT + 3
    ports.release_all(b)
    assert len(ports) == 0 and ports.held(b) == frozenset()


def test_a_wish_is_granted_when_free_and_not_served() -> None:
    ports = ClientPorts(reserved={851})
    a, b = object(), object()
    assert ports.register(a, 30000) == 30000  # below the pool: a client's own choice
    assert ports.register(b, FIRST_CLIENT_PORT) == FIRST_CLIENT_PORT
    assert ports.register(b) == FIRST_CLIENT_PORT + 1  # the wished one is skipped
    with pytest.raises(PortRefused, match="port 30000 is in use"):
        ports.register(b, 30000)
    with pytest.raises(PortRefused, match="port 851 is one the service serves"):
        ports.register(b, 851)
    ports.release(b, FIRST_CLIENT_PORT)
    assert ports.register(a, FIRST_CLIENT_PORT) == FIRST_CLIENT_PORT  # taken by wish
    assert ports.register(a) == FIRST_CLIENT_PORT + 2  # not handed out twice


def test_exhaustion_is_refused_saying_why() -> None:
    ports = ClientPorts(first=40000, last=40002, per_owner=2)
    owners = [object() for _ in range(3)]
    assert ports.register(owners[0]) == 40000 and ports.register(owners[0]) == 40001
    with pytest.raises(PortRefused, match="holds 2 ports already"):
        ports.register(owners[0])
    assert ports.register(owners[1]) == 40002
    with pytest.raises(PortRefused, match=r"all 3 client ports \(40000\.\.40002\) are in use"):
        ports.register(owners[2])
    ports.release_all(owners[0])
    assert ports.register(owners[2]) == 40000
