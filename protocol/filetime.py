"""Windows FILETIME, the time stamp of ADS notifications: 100 ns ticks since
1601-01-01 00:00 UTC. The service encodes it, clients decode it; both use this module."""

from __future__ import annotations

from datetime import UTC, datetime, timedelta

#: FILETIME of the Unix epoch (1970-01-01 00:00 UTC).
FILETIME_UNIX_EPOCH = 116_444_736_000_000_000
_FILETIME_EPOCH = datetime(1601, 1, 1, tzinfo=UTC)
_NS_PER_TICK = 100


def filetime_from_unix_ns(unix_ns: int) -> int:
    """A wall-clock time (ns since the Unix epoch) as a FILETIME."""
    return FILETIME_UNIX_EPOCH + unix_ns // _NS_PER_TICK


def filetime_to_datetime(filetime: int) -> datetime:
    """A FILETIME as an aware UTC datetime (to the microsecond)."""
    return _FILETIME_EPOCH + timedelta(microseconds=filetime // 10)
