"""What the access-control tests share."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cnc_objects.testing import ServiceProcess, start_service


@pytest.fixture(scope="module")
def keyed() -> Iterator[ServiceProcess]:
    """One service with keys per test module (its tests only grow programs and feed
    overrides); it must stop cleanly."""
    service = start_service(keys=True)
    try:
        yield service
    finally:
        assert service.stop() == 0, service.log_text
