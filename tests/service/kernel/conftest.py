"""Fixtures of the kernel tests: one real kernel per test module, on the virtual clock."""

from __future__ import annotations

import pytest

from tests.support.kernel import KernelHarness


@pytest.fixture(scope="module")
def kernel():
    """A started kernel on the default machine, shared by the tests of a module."""
    with KernelHarness() as harness:
        yield harness
