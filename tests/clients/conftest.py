"""Fixtures of the client tests: a broker of the test's own."""

from __future__ import annotations

from collections.abc import AsyncIterator

import pytest

from tests.support.broker import Broker, running_broker


@pytest.fixture
async def broker() -> AsyncIterator[Broker]:
    """A broker of this test only: Mosquitto when installed, else amqtt."""
    async with running_broker() as running:
        yield running
