"""The names our tests have used for the service starter, which lives once, in the
pytest plugin (``cnc_objects.testing.process``): ``start_service(*args)`` and
``serving(*args)`` for tests that need ``cnc-service`` options of their own;
``RunningService`` is ``ServiceProcess``. ``ROOT`` is the repository root."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path

from cnc_objects.clients import Client
from cnc_objects.testing import ServiceProcess as RunningService
from cnc_objects.testing import serving, start_service

ROOT = Path(__file__).resolve().parents[2]

__all__ = ["ROOT", "RunningService", "home_channel", "reset_client", "serving",
           "serving_config", "start_service"]


@contextlib.contextmanager
def serving_config(work: Path, machine_toml: str, *args: str) -> Iterator[RunningService]:
    """``serving`` with a machine configuration written to ``work`` (its programs there too)."""
    path = work / "machine.toml"
    path.write_text(machine_toml)
    with serving("--config", str(path), *args, program_dir=work / "programs") as service:
        yield service


@contextlib.contextmanager
def reset_client(service: RunningService, timeout_s: float = 10.0) -> Iterator[Client]:
    """A blocking client of ``service`` whose channel 1 has just been RESET."""
    with Client(service.endpoint, timeout_s=timeout_s) as client:
        client.reset(1)
        yield client


def home_channel(endpoint: str, channel: int = 1, axes: str = "X1 Y1 Z1") -> None:
    """Home the axes of ``channel`` (``G74`` in MDI, the default machine's X Y Z): from
    then on their software limits are monitored (P-AXIS-00705, ISG's default)."""
    with Client(endpoint, timeout_s=30.0) as client:
        before = client.mdi(f"G74 {axes}", channel)
        client.wait_mdi(before, channel, timeout_s=60.0)
