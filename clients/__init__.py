"""Clients of a cnc-objects service: async and blocking library, ``cnc`` CLI.

    from cnc_objects.clients import AdsState, Client

    with Client("tcp://127.0.0.1:5555") as c:
        c.write_control(AdsState.STOP)   # or "stop"

Imports protocol and objects, never service.
"""

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
)
from .execution_mode import describe_execution_mode
from .path_trace import PathTrace

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
    "describe_execution_mode",
    "filetime_to_datetime",
]
