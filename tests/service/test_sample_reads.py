"""The sampling path's short-way reads (service/sample_reads.py, issue 37).

The backend is the one the service builds over the default machine's kernel (not
started; its first snapshot is what every getter reads). A subscription to an object's
whole value is sampled through the object's getter and encoder instead of the read
dispatcher: for every readable object, by address and by handle, the short way must give
the bytes the dispatcher answers; every other read has no short way. An on-change sample
skips the encoding only when the value surely encodes to the same bytes.
"""

from __future__ import annotations

import asyncio
import math
import struct
from collections.abc import Iterator

import pytest

from cnc_objects.objects.catalog import PLC_GROUP
from cnc_objects.objects.plc_structs import PlcStructs
from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.constants import ReservedIndexGroup as RIG
from cnc_objects.protocol.datatypes import REAL64, SGN32
from cnc_objects.service.ads.symbols import SymbolService
from cnc_objects.service.backend import Backend
from cnc_objects.service.binding import build_address_space
from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.clock import VirtualClock
from cnc_objects.service.kernel.kernel import Kernel
from cnc_objects.service.sample_reads import encoder_of, unchanged


@pytest.fixture(scope="module")
def backend() -> Iterator[Backend]:
    config = build_config()
    kernel = Kernel(config, VirtualClock(config.cycle_ms / 1000.0))
    space = build_address_space(kernel)
    structs = PlcStructs(space)
    loop = asyncio.new_event_loop()
    yield Backend(space, kernel, loop, symbols=SymbolService(space, structs), structs=structs)
    loop.close()


def test_the_short_way_reads_what_the_dispatcher_reads(backend: Backend) -> None:
    """Every readable object, by its address (with its size) and by its handle (with its
    size and with a larger buffer): the getter's value, encoded, is the dispatcher's
    answer, byte for byte."""
    checked = 0
    for entry in backend.space._entries:
        obj = entry.obj
        if entry.read is None:
            continue
        size = obj.dtype.size
        for port, group, offset, length in (
                (obj.port, obj.group, obj.offset, size),
                (obj.port, RIG.SYM_VALUE_BY_HANDLE, entry.handle, size),
                (obj.port, RIG.SYM_VALUE_BY_HANDLE, entry.handle, size + 16)):
            code, expected = backend.read_value(port, group, offset, length)
            found = backend.direct_read(port, group, offset, length)
            if code:  # a getter that cannot answer here has no short way to a value either
                continue
            assert found is not None, (obj.name, group)
            getter, encode = found
            assert encode(getter()) == expected, (obj.name, group)
            checked += 1
    assert checked > 3 * 1000


def test_other_reads_have_no_short_way(backend: Backend) -> None:
    """A string read into a shorter buffer, a wrong size, a range of the PLC memory area,
    the device data, the symbol services, an unknown address: read by the dispatcher."""
    space = backend.space
    text = next(e for e in space._entries if e.obj.dtype.kind == "str" and e.read is not None)
    number = space.by_name("ch1.ax1.command_position_acs")
    plc = next(e for e in space._entries
               if e.obj.port == CncPort.PLC and e.obj.group == PLC_GROUP and e.read is not None)
    assert number is not None
    o = number.obj
    for address in (
            (text.obj.port, text.obj.group, text.obj.offset, 4),
            (text.obj.port, RIG.SYM_VALUE_BY_HANDLE, text.handle, 4),
            (o.port, o.group, o.offset, o.dtype.size + 1),
            (o.port, RIG.SYM_VALUE_BY_HANDLE, number.handle, o.dtype.size - 1),
            (plc.obj.port, plc.obj.group, plc.obj.offset, plc.obj.dtype.size + 64),
            (CncPort.PLC, RIG.DEVICE_DATA, 0, 4),
            (CncPort.PLC, RIG.SYM_UPLOAD_INFO2, 0, 24),
            (o.port, o.group, 0x7FFF_FFF0, 8),
            (o.port, RIG.SYM_VALUE_BY_HANDLE, 0x7FFF_FFF0, 8)):
        assert backend.direct_read(*address) is None, address


def test_unchanged_only_when_the_bytes_are_surely_the_same() -> None:
    """Equal numbers that encode differently (0.0 and -0.0, True and 1) and NaNs that are
    not the same object count as changed; equal ints and texts, and the same object, do
    not."""
    nan = float("nan")
    big = 10**12
    assert unchanged(nan, nan)
    assert not unchanged(nan, float("nan"))
    assert not unchanged(0.0, -0.0)
    assert not unchanged(True, 1)
    assert not unchanged(1, 1.0)
    assert unchanged(big + 1, int(str(big + 1)))
    assert unchanged("ab", "".join(["a", "b"]))
    assert math.isnan(nan) and not unchanged(nan, 0.0)


def test_a_real64_float_is_packed_as_encode_packs_it() -> None:
    """The REAL64 fast path gives ``encode``'s bytes, and anything but a float takes
    ``encode`` (which refuses what it refuses)."""
    fast = encoder_of(REAL64)
    for value in (0.0, -0.0, 1e300, -2.5, float("inf"), float("nan"), 3):
        assert fast(value) == REAL64.encode(value)
    assert fast(-0.0) == struct.pack("<d", -0.0)
    with pytest.raises(TypeError):
        fast(True)
    assert encoder_of(SGN32) == SGN32.encode
