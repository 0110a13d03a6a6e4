"""Clients of a cnc-objects service: async and blocking library, ``cnc`` CLI.

Imports protocol and objects, never service.
"""

from .client import (
    AsyncClient,
    ChannelStatus,
    Client,
    DeviceInfo,
    ObjectInfo,
    ProgramEntry,
    Sample,
)
from .errors import AdsConnectionError, AdsError, AdsTimeoutError, ChannelError

__all__ = [
    "AdsConnectionError",
    "AdsError",
    "AdsTimeoutError",
    "AsyncClient",
    "ChannelError",
    "ChannelStatus",
    "Client",
    "DeviceInfo",
    "ObjectInfo",
    "ProgramEntry",
    "Sample",
]
