"""Clients of a cnc-objects service: async and blocking library, ``cnc`` CLI.

Imports protocol and objects, never service.
"""

from .client import AsyncClient, Client, DeviceInfo, ObjectInfo, Sample
from .errors import AdsConnectionError, AdsError, AdsTimeoutError

__all__ = [
    "AdsConnectionError",
    "AdsError",
    "AdsTimeoutError",
    "AsyncClient",
    "Client",
    "DeviceInfo",
    "ObjectInfo",
    "Sample",
]
