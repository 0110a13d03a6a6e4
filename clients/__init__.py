"""Clients of a cnc-objects service: async and blocking library, ``cnc`` CLI.

    from cnc_objects.clients import AdsState, Client

    with Client("tcp://127.0.0.1:5555") as c:
        c.write_control(AdsState.STOP)   # or "stop"

Imports protocol and objects, never service.

The names below are imported on first use (PEP 562 ``__getattr__``), not with the
package: ``cnc --help`` imports ``cnc_objects.clients.cli`` and thereby this package, and
must not pay for zmq, asyncio and numpy, which the client library needs
(docs/design-notes.md, "A quick cnc").
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from cnc_objects.protocol.constants import AdsState
    from cnc_objects.protocol.errors import AdsReturnCode
    from cnc_objects.protocol.values import ExecutionMode

    from .alarm_ops import AlarmEvent, AlarmInfo, AlarmList
    from .blocking import Client
    from .channel_ops import ContourBlock, ContourReply
    from .client import (
        DEFAULT_ENDPOINT,
        AsyncClient,
        ChannelStatus,
        CheckError,
        CheckResult,
        DeviceInfo,
        ObjectInfo,
        ProgramEntry,
        Sample,
        filetime_to_datetime,
    )
    from .errors import (
        AdsConnectionError,
        AdsError,
        AdsTimeoutError,
        AuthenticationError,
        ChannelError,
        ClientValueError,
        NoReplyError,
        ServiceFullError,
    )
    from .execution_mode import describe_execution_mode
    from .path_trace import PathTrace

# Each public name -> the module that defines it (imported when the name is first asked).
_SOURCES = {
    "AdsState": "cnc_objects.protocol.constants",
    "AdsReturnCode": "cnc_objects.protocol.errors",
    "ExecutionMode": "cnc_objects.protocol.values",
    "Client": f"{__name__}.blocking",
    **dict.fromkeys(("AlarmEvent", "AlarmInfo", "AlarmList"), f"{__name__}.alarm_ops"),
    **dict.fromkeys(("ContourBlock", "ContourReply"), f"{__name__}.channel_ops"),
    **dict.fromkeys((
        "DEFAULT_ENDPOINT", "AsyncClient", "ChannelStatus", "CheckError", "CheckResult",
        "DeviceInfo", "ObjectInfo", "ProgramEntry", "Sample", "filetime_to_datetime",
    ), f"{__name__}.client"),
    **dict.fromkeys((
        "AdsConnectionError", "AdsError", "AdsTimeoutError", "AuthenticationError",
        "ChannelError", "ClientValueError", "NoReplyError", "ServiceFullError",
    ), f"{__name__}.errors"),
    "describe_execution_mode": f"{__name__}.execution_mode",
    "PathTrace": f"{__name__}.path_trace",
}


def __getattr__(name: str) -> Any:
    """A public name of the package, imported from its module on first use."""
    try:
        module = _SOURCES[name]
    except KeyError:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # the next access is a plain lookup
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *_SOURCES])


__all__ = [
    "DEFAULT_ENDPOINT",
    "AdsConnectionError",
    "AdsError",
    "AdsReturnCode",
    "AdsState",
    "AdsTimeoutError",
    "AlarmEvent",
    "AlarmInfo",
    "AlarmList",
    "AsyncClient",
    "AuthenticationError",
    "ChannelError",
    "ChannelStatus",
    "CheckError",
    "CheckResult",
    "Client",
    "ClientValueError",
    "ContourBlock",
    "ContourReply",
    "DeviceInfo",
    "ExecutionMode",
    "NoReplyError",
    "ObjectInfo",
    "PathTrace",
    "ProgramEntry",
    "Sample",
    "ServiceFullError",
    "describe_execution_mode",
    "filetime_to_datetime",
]
