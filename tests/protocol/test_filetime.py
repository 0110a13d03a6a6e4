"""FILETIME, the one contract of notification time stamps, encoded by the service and
decoded by clients from the same module."""

from datetime import UTC, datetime

from hypothesis import given
from hypothesis import strategies as st

from cnc_objects.protocol.filetime import (
    FILETIME_UNIX_EPOCH,
    filetime_from_unix_ns,
    filetime_to_datetime,
)


def test_the_unix_epoch_is_its_documented_filetime() -> None:
    assert filetime_from_unix_ns(0) == FILETIME_UNIX_EPOCH
    assert filetime_to_datetime(FILETIME_UNIX_EPOCH) == datetime(1970, 1, 1, tzinfo=UTC)


def test_a_known_instant() -> None:
    instant = datetime(2026, 11, 27, 5, 18, 34, 123456, tzinfo=UTC)
    unix_ns = int(instant.timestamp()) * 1_000_000_000 + 123_456_000
    assert filetime_to_datetime(filetime_from_unix_ns(unix_ns)) == instant


@given(st.integers(min_value=0, max_value=2**62))
def test_decoding_an_encoded_time_keeps_its_microseconds(unix_ns: int) -> None:
    decoded = filetime_to_datetime(filetime_from_unix_ns(unix_ns))
    micros = (decoded - datetime(1970, 1, 1, tzinfo=UTC)) // _MICROSECOND
    assert micros == unix_ns // 1000


_MICROSECOND = datetime(1970, 1, 1, 0, 0, 0, 1, tzinfo=UTC) - datetime(1970, 1, 1, tzinfo=UTC)
