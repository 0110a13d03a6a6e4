"""Fixtures of the raw-ADS tests that talk TwinCAT 3's conventions (read length, handles,
structs, framing): one service with ADS per test module, a fresh AMS/TCP connection per test.
A module that defines its own ``ads_service`` or ``ads`` uses that one instead."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cnc_objects.testing import ServiceProcess, start_service
from tests.support.ads_raw import RawAds


@pytest.fixture(scope="module")
def ads_service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    """A service with ADS on a free loopback port, for the module."""
    running = start_service(program_dir=tmp_path_factory.mktemp("ads"), ads="127.0.0.1:0")
    yield running
    assert running.stop() == 0, running.log_text


@pytest.fixture
def ads(ads_service: ServiceProcess) -> Iterator[RawAds]:
    """A fresh AMS/TCP connection to ``ads_service``, as a new client's."""
    connection = RawAds(ads_service)
    yield connection
    connection.close()
