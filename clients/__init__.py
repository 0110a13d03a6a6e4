"""Clients of a cnc-objects service: async and blocking library, ``cnc`` CLI.

Imports protocol and objects, never service.
"""

from .client import (
    AsyncClient,
    ChannelStatus,
    CheckError,
    CheckResult,
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
    "CheckError",
    "CheckResult",
    "Client",
    "DeviceInfo",
    "ObjectInfo",
    "ProgramEntry",
    "Sample",
]
