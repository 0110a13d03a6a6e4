"""Fixtures: real services over real sockets, on free ports, with the virtual clock.

The services come from our own pytest plugin (``cnc_objects.testing``, loaded through its
entry point); ``service`` and ``shared_service`` are the names our tests have used for
its ``cnc_service`` and ``cnc_shared_service``.
"""

from __future__ import annotations

import os

import pytest
from hypothesis import settings

from cnc_objects.testing import ServiceProcess
from tests.support.network import own_non_loopback_ipv4

pytest_plugins = ["pytester"]  # the plugin's own tests run pytest on small test files

# CI (`.ci/run` sets CI) runs the same hypothesis examples every time: a submission's
# checks do not depend on which random examples that run drew (a random run found a
# 3e-162 mm triangle once). Elsewhere hypothesis explores, and what it finds is kept.
settings.register_profile("ci", derandomize=True, database=None)
if os.environ.get("CI"):
    settings.load_profile("ci")


@pytest.fixture
def service(cnc_service: ServiceProcess) -> ServiceProcess:
    """A fresh service for one test: its writes do not leak into other tests."""
    return cnc_service


@pytest.fixture(scope="session")
def shared_service(cnc_shared_service: ServiceProcess) -> ServiceProcess:
    """One service for tests that only read (or restore what they write)."""
    return cnc_shared_service


@pytest.fixture
def endpoint(shared_service: ServiceProcess) -> str:
    """Endpoint of the shared service."""
    return shared_service.endpoint


@pytest.fixture
def non_loopback_ipv4() -> str:
    """This machine's IPv4 address that is not loopback (a peer the loopback rule does
    not cover); the test is skipped, saying why, on a machine that has none."""
    address = own_non_loopback_ipv4()
    if address is None:
        pytest.skip("this machine has no IPv4 address besides loopback")
    return address
