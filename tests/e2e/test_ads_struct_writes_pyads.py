"""Every struct symbol takes its own bytes back, at its address and by handle (issue 41,
item 2), with pyads as the client: TwinCAT writes %M memory byte for byte, and ADS
clients write structs at their address (``plc.write(0x4020, offset, raw, c_ubyte * n)``)
or as Node-RED's ads-client does, the struct read first and one member changed.

The rule for the other bytes (docs/ads.md, "Struct writes"): padding ignored; read-only
members ignored where the struct has a writable member; a struct without one takes only
the bytes it holds.
"""

from __future__ import annotations

import ctypes
import struct
from collections.abc import Callable, Iterator

import pyads
import pytest

from cnc_objects.protocol.ads_symbols import AdsDataType, SymbolEntry, decode_symbol_entries
from tests.support.pyads_plc import pyads_service

LOCAL_NET_ID = "127.0.0.1.1.41"  # this test process, as pyads' AMS router
PLC_GROUP = 0x4020
INVALIDACCESS = 0x704
SPINDLE = "gpCh[0].spindle"  # mode_r (UINT, read-only) first, then override_w (UINT)


@pytest.fixture(scope="module")
def plc(tmp_path_factory: pytest.TempPathFactory) -> Iterator[pyads.Connection]:
    with pyads_service(tmp_path_factory.mktemp("struct-writes"), LOCAL_NET_ID) as (_, (plc,)):
        yield plc


def struct_symbols(plc: pyads.Connection) -> list[SymbolEntry]:
    """The struct and array symbols of the upload (0xF00F info, 0xF00B upload)."""
    info = bytes(plc.read(0xF00F, 0, ctypes.c_ubyte * 24, return_ctypes=True))
    size = struct.unpack_from("<I", info, 4)[0]
    upload = bytes(plc.read(0xF00B, 0, ctypes.c_ubyte * size, return_ctypes=True))
    return [s for s in decode_symbol_entries(upload) if s.data_type == AdsDataType.BIGTYPE]


def raw(plc: pyads.Connection, entry: SymbolEntry) -> bytes:
    return bytes(plc.read(entry.group, entry.offset, ctypes.c_ubyte * entry.size,
                          return_ctypes=True))


def test_every_struct_symbol_takes_its_own_bytes_back_at_its_address(plc: pyads.Connection) -> None:
    symbols = struct_symbols(plc)
    assert len(symbols) > 100 and SPINDLE in {s.name for s in symbols}
    refused = []
    for entry in symbols:
        assert entry.group == PLC_GROUP, entry.name
        data = raw(plc, entry)
        try:
            plc.write(entry.group, entry.offset, list(data), ctypes.c_ubyte * entry.size)
        except pyads.ADSError as exc:
            refused.append((entry.name, hex(exc.err_code)))
        assert raw(plc, entry) == data, entry.name
    assert refused == []


def test_every_struct_symbol_takes_its_own_bytes_back_by_handle(plc: pyads.Connection) -> None:
    refused = []
    for entry in struct_symbols(plc):
        kind = ctypes.c_ubyte * entry.size
        handle = plc.get_handle(entry.name)
        try:
            data = list(plc.read_by_name("", kind, handle=handle))
            plc.write_by_name("", data, kind, handle=handle)
        except pyads.ADSError as exc:
            refused.append((entry.name, hex(exc.err_code)))
        finally:
            plc.release_handle(handle)
    assert refused == []


def test_a_changed_read_only_member_changes_nothing_and_the_writable_one_is_written(
        plc: pyads.Connection) -> None:
    """Node-RED's write of ``{"override_w": 500}``: the struct read, one member changed,
    written back; a read-only member sent changed is ignored, kernel state unchanged."""
    entry = next(s for s in struct_symbols(plc) if s.name == SPINDLE)
    before = raw(plc, entry)
    mode_r, override_w = struct.unpack_from("<HH", before)
    changed = bytearray(before)
    struct.pack_into("<HH", changed, 0, mode_r ^ 0xFF, 500)  # mode_r is read-only
    changed[0x11:0x18] = b"\xee" * 7  # padding
    try:
        plc.write(PLC_GROUP, entry.offset, list(changed), ctypes.c_ubyte * entry.size)
        assert plc.read_by_name(f"{SPINDLE}.override_w", pyads.PLCTYPE_UINT) == 500
        assert plc.read_by_name(f"{SPINDLE}.mode_r", pyads.PLCTYPE_UINT) == mode_r
        assert raw(plc, entry)[0x11:0x18] == bytes(7)
    finally:
        plc.write_by_name(f"{SPINDLE}.override_w", override_w, pyads.PLCTYPE_UINT)


def test_a_struct_with_nothing_writable_refuses_other_bytes(plc: pyads.Connection) -> None:
    entry = next(s for s in struct_symbols(plc) if s.name == "gpAx[0].lr_state")
    before = raw(plc, entry)
    changed = bytes([before[0] ^ 1]) + before[1:]
    writes: list[Callable[[], object]] = [
        lambda: plc.write(PLC_GROUP, entry.offset, list(changed), ctypes.c_ubyte * entry.size),
        lambda: plc.write_by_name(entry.name, list(changed), ctypes.c_ubyte * entry.size),
    ]
    for write in writes:
        with pytest.raises(pyads.ADSError) as refused:
            write()
        assert refused.value.err_code == INVALIDACCESS
    assert raw(plc, entry) == before
