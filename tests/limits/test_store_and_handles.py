"""``[limits] program_max_bytes`` and ``program_max_files`` reach the program store; handles
are no per-client resource (there is no handle limit: nothing to limit)."""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from cnc_objects.clients import AdsError, Client
from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.constants import ReservedIndexGroup as RIG
from cnc_objects.protocol.frames import ReadWriteRequest, WriteRequest
from cnc_objects.testing import serving
from tests.limits.wire import Raw, limited_service, next_id

INVALIDSIZE, NOMEMORY = 0x705, 0x70A


def test_the_program_store_takes_the_configured_size_and_count(tmp_path: Path) -> None:
    with limited_service(tmp_path, program_max_bytes=1000, program_max_files=2) as service, \
            Client(service.endpoint) as cnc:
        cnc.upload("a.nc", b";" * 1000)
        with pytest.raises(AdsError) as caught:
            cnc.upload("b.nc", b";" * 1001)
        assert caught.value.code == INVALIDSIZE and "at most 1000" in str(caught.value)
        cnc.upload("b.nc", b"M30\n")
        with pytest.raises(AdsError) as caught:
            cnc.upload("c.nc", b"M30\n")
        assert caught.value.code == NOMEMORY and "holds 2 files" in str(caught.value)
        cnc.upload("b.nc", b"M02\n")  # replacing a file is no new file
        assert [p.name for p in cnc.programs()] == ["a.nc", "b.nc"]


def handle_of(client: Raw, name: str) -> int:
    reply = client.call(ReadWriteRequest(next_id(), CncPort.COM, RIG.SYM_HANDLE_BY_NAME, 0, 4,
                                         name.encode() + b"\x00").encode())
    assert reply[2] == 0, reply
    return struct.unpack("<I", reply[3])[0]


def test_a_handle_is_the_objects_own_number_the_same_for_every_client() -> None:
    """Handles by name cost nothing per client: a handle is the object's stable number,
    asking again hands out the same one, and releasing it frees nothing another client
    could miss."""
    with serving() as service, Raw(service.endpoint) as a, Raw(service.endpoint) as b:
        handle = handle_of(a, "cnc_tick_counter_r")
        assert {handle_of(a, "cnc_tick_counter_r") for _ in range(1000)} == {handle}
        assert handle_of(b, "cnc_tick_counter_r") == handle
        release = WriteRequest(next_id(), CncPort.COM, RIG.SYM_RELEASE_HANDLE, 0,
                               struct.pack("<I", handle)).encode()
        assert a.call(release)[2] == 0
        assert len(b.read((CncPort.COM, RIG.SYM_VALUE_BY_HANDLE, handle), 4)) == 4
