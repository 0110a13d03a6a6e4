"""Fixtures: real services over real sockets, on free ports, with the virtual clock."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from tests.support.service import RunningService, start_service


@pytest.fixture(scope="session")
def shared_service() -> Iterator[RunningService]:
    """One service for tests that only read (or restore what they write)."""
    service = start_service()
    yield service
    assert service.stop() == 0, "\n".join(service.log)


@pytest.fixture
def service() -> Iterator[RunningService]:
    """A fresh service for one test: its writes do not leak into other tests."""
    service = start_service()
    yield service
    assert service.stop() == 0, "\n".join(service.log)


@pytest.fixture
def endpoint(shared_service: RunningService) -> str:
    """Endpoint of the shared service."""
    return shared_service.endpoint
