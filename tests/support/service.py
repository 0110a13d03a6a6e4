"""The names our tests have used for the service starter, which lives once, in the
pytest plugin (``cnc_objects.testing.process``): ``start_service(*args)`` and
``serving(*args)`` for tests that need ``cnc-service`` options of their own;
``RunningService`` is ``ServiceProcess``. ``ROOT`` is the repository root."""

from __future__ import annotations

from pathlib import Path

from cnc_objects.testing import ServiceProcess as RunningService
from cnc_objects.testing import serving, start_service

ROOT = Path(__file__).resolve().parents[2]

__all__ = ["ROOT", "RunningService", "serving", "start_service"]
