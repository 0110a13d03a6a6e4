"""A pytest plugin for integration tests against a real ``cnc-service``.

Installed with cnc-objects and loaded by pytest through the ``pytest11`` entry point:
no ``conftest.py`` is needed. See ``docs/testing.md``.

Fixtures:

- ``cnc_service``: a ``cnc-service`` of this test (virtual clock, free loopback port,
  empty program store), configured by ``@pytest.mark.cnc_service(config=..., programs=[...],
  args=[...])``; stopped at teardown, and a service that does not exit 0 fails the test.
- ``cnc_shared_service``: one service for the whole session.
- ``cnc_client``: a blocking ``Client`` connected to ``cnc_service``.
- ``cnc_async_client``: an ``AsyncClient`` connected to ``cnc_service`` (pytest-asyncio).
- ``cnc_alarms``: the alarms ``cnc_service`` raised during the test (``AlarmRecorder``:
  ``raised_ids()``, ``active_ids()``, ``wait_for(id)``, ``clear()``).
- ``cnc_trace``: a program run's samples as (kernel time ns, object, value) rows, the same
  in every run (``TraceRecorder``: ``watch([...], cycle_ms, on_change)``, ``run(program)``;
  ``cnc_service`` then runs with ``--samples repeatable``).

Helpers (imported from here on first use, so that loading the plugin stays cheap):
``run_program`` / ``run_program_async`` run a program to its end, ``wait_for`` /
``wait_for_async`` wait until an object has a value; ``start_service`` / ``serving`` start a
service by hand (``ServiceProcess``).
"""

from __future__ import annotations

from typing import Any

from .plugin import (
    cnc_alarms,
    cnc_async_client,
    cnc_client,
    cnc_service,
    cnc_shared_service,
    cnc_trace,
    pytest_configure,
    pytest_runtest_makereport,
)
from .process import ServiceProcess, serving, start_service

_HELPERS = frozenset({"run_program", "run_program_async", "wait_for", "wait_for_async"})

__all__ = [
    "ServiceProcess", "cnc_alarms", "cnc_async_client", "cnc_client", "cnc_service", "cnc_shared_service",
    "cnc_trace", "pytest_configure", "pytest_runtest_makereport", "run_program", "run_program_async",
    "serving", "start_service", "wait_for", "wait_for_async",
]


def __getattr__(name: str) -> Any:
    """The helpers, imported on first use: they need the client library (ZeroMQ, ...),
    which pytest should not import in projects that never use them."""
    if name in _HELPERS:
        from . import helpers

        return getattr(helpers, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
