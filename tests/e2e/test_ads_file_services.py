"""TwinCAT's file functions at the system service (port 10000) on the program store, as
Tc2_System's FB_FileOpen/Read/Write/Close/Delete and AdsLib's ``AdsFile`` send them:
pyads (the reference client) writes a CAM program of several frames and reads it back;
frames built by hand (``test_ads_raw``) show the errors and that a connection closed in
the middle of a write leaves nothing behind."""

from __future__ import annotations

import hashlib
import struct
from collections.abc import Iterator
from pathlib import Path

import pyads
import pytest

from cnc_objects.testing import ServiceProcess, serving
from tests.limits.wire import limited_service
from tests.support.ads_raw import READ_WRITE, SYSTEM, RawAds, read_write
from tests.support.pyads_plc import pyads_service

FOPEN, FCLOSE, FREAD, FWRITE, FDELETE = 120, 121, 122, 123, 131
MODE_READ, MODE_WRITE, MODE_APPEND, MODE_PLUS, MODE_BINARY = 0x1, 0x2, 0x4, 0x8, 0x10
PATH_GENERIC = 1 << 16
LOCAL_NET_ID = "127.0.0.1.1.23"  # this test process, as pyads' AMS router
CHUNK_BYTES = 60_000  # what a PLC's FB_FileWrite buffer might hold
PROGRAM = b"".join(b"N%d G1 X%.3f Y%.3f Z-1 F1200\n" % (n, n % 997 / 10, n % 313 / 10)
                   for n in range(100_000))


def leftovers(program_dir: Path) -> list[str]:
    return sorted(p.name for p in program_dir.iterdir() if p.name.startswith("."))


@pytest.fixture(scope="module")
def system(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[ServiceProcess, pyads.Connection]]:
    with pyads_service(tmp_path_factory.mktemp("ads-files"), LOCAL_NET_ID,
                       ports=(10000,)) as (service, (connection,)):
        yield service, connection


def _open(connection: pyads.Connection, name: str, flags: int) -> int:
    handle = connection.read_write(FOPEN, flags, pyads.PLCTYPE_UDINT, name, pyads.PLCTYPE_STRING)
    assert isinstance(handle, int) and 0 < handle <= 0xFFFF  # hFile is a UINT in the PLC
    return handle


def test_pyads_writes_a_program_of_several_frames_and_reads_it_back(
        system: tuple[ServiceProcess, pyads.Connection]) -> None:
    service, ads = system
    assert len(PROGRAM) > 2_500_000
    handle = _open(ads, "cam.nc", MODE_WRITE | MODE_BINARY | PATH_GENERIC)
    for start in range(0, len(PROGRAM), CHUNK_BYTES):
        chunk = PROGRAM[start:start + CHUNK_BYTES]
        ads.read_write(FWRITE, handle, None, chunk, pyads.PLCTYPE_BYTE * len(chunk))
        assert not (service.program_dir / "cam.nc").exists()  # nothing before FCLOSE
    ads.read_write(FCLOSE, handle, None, None, None)
    stored = (service.program_dir / "cam.nc").read_bytes()
    assert hashlib.sha256(stored).digest() == hashlib.sha256(PROGRAM).digest()
    assert leftovers(service.program_dir) == []

    handle = _open(ads, "cam.nc", MODE_READ | MODE_BINARY | PATH_GENERIC)
    got = b""
    while len(PROGRAM) - len(got) >= 1_000_000:
        got += bytes(ads.read_write(FREAD, handle, pyads.PLCTYPE_BYTE * 1_000_000, None, None,
                                    return_ctypes=True))
    rest = len(PROGRAM) - len(got)
    with pytest.raises(RuntimeError, match=f"expected 1000000 bytes, {rest} were read"):
        ads.read_write(FREAD, handle, pyads.PLCTYPE_BYTE * 1_000_000, None, None)
    ads.read_write(FCLOSE, handle, None, None, None)
    handle = _open(ads, "cam.nc", MODE_READ | PATH_GENERIC)
    for _ in range((len(PROGRAM) - rest) // 1_000_000):
        ads.read_write(FREAD, handle, pyads.PLCTYPE_BYTE * 1_000_000, None, None)
    got += bytes(ads.read_write(FREAD, handle, pyads.PLCTYPE_BYTE * rest, None, None,
                                return_ctypes=True))
    with pytest.raises(RuntimeError, match="expected 10 bytes, 0 were read"):  # the end
        ads.read_write(FREAD, handle, pyads.PLCTYPE_BYTE * 10, None, None)
    ads.read_write(FCLOSE, handle, None, None, None)
    assert got == PROGRAM

    ads.read_write(FDELETE, PATH_GENERIC, None, "cam.nc", pyads.PLCTYPE_STRING)
    assert not (service.program_dir / "cam.nc").exists()


def test_pyads_gets_the_ads_error_of_each_bad_open(
        system: tuple[ServiceProcess, pyads.Connection]) -> None:
    _, ads = system
    cases = [
        ("missing.nc", MODE_READ | PATH_GENERIC, 0x70C),  # not found (files, ...)
        ("x.nc", MODE_WRITE | (3 << 16), 0x70C),  # PATH_BOOTDATA: not served
        ("x.nc", MODE_APPEND | PATH_GENERIC, 0x706),  # the store replaces programs whole
        ("x.nc", MODE_READ | MODE_PLUS | PATH_GENERIC, 0x706),
        ("x.nc", MODE_READ | MODE_WRITE | PATH_GENERIC, 0x706),
        ("../etc/passwd", MODE_READ | PATH_GENERIC, 0x706),  # a store name, no directories
    ]
    for name, flags, code in cases:
        with pytest.raises(pyads.ADSError) as raised:
            ads.read_write(FOPEN, flags, pyads.PLCTYPE_UDINT, name, pyads.PLCTYPE_STRING)
        assert raised.value.err_code == code, (name, hex(flags))


def _call(ads: RawAds, group: int, offset: int, read_length: int, data: bytes) -> tuple[int, bytes]:
    reply = ads.call(READ_WRITE, read_write(group, offset, read_length, data), port=SYSTEM)
    code, length = struct.unpack_from("<II", reply.data)
    return code, reply.data[8:8 + length]


def _handle(ads: RawAds, name: bytes, flags: int) -> int:
    """FOPEN of ``name``: its handle (the open must succeed)."""
    code, data = _call(ads, FOPEN, flags, 4, name + b"\x00")
    assert code == 0, hex(code)
    return int(struct.unpack("<I", data)[0])


def test_handles_belong_to_their_connection_and_bad_ones_are_refused(
        ads: RawAds, ads_service: ServiceProcess) -> None:
    (ads_service.program_dir / "part.nc").write_bytes(b"G1 X1\nM30\n")
    handle = _handle(ads, b"part.nc", MODE_READ | PATH_GENERIC)
    assert _call(ads, FREAD, handle, 2_000_000, b"")[0] == 0x705  # more than one frame
    assert _call(ads, FWRITE, handle, 0, b"G0\n")[0] == 0x706  # open for reading
    other = RawAds(ads_service)
    try:
        assert _call(other, FREAD, handle, 10, b"")[0] == 0x703  # not its handle
    finally:
        other.close()
    assert _call(ads, FREAD, handle, 100, b"") == (0, b"G1 X1\nM30\n")
    assert _call(ads, FCLOSE, handle, 0, b"") == (0, b"")
    assert _call(ads, FCLOSE, handle, 0, b"")[0] == 0x703  # closed
    assert _call(ads, 125, handle, 4, b"")[0] == 0x701  # FTELL: not served


def test_a_connection_closed_in_the_middle_of_a_write_leaves_nothing(
        ads_service: ServiceProcess) -> None:
    (ads_service.program_dir / "kept.nc").write_bytes(b"G1 X2\nM30\n")
    connection = RawAds(ads_service)
    try:
        handle = _handle(connection, b"kept.nc", MODE_WRITE | PATH_GENERIC)
        assert _call(connection, FWRITE, handle, 0, b"G1 X9\n" * 1000) == (0, b"")
        assert len(leftovers(ads_service.program_dir)) == 1
    finally:
        connection.close()
    ads_service.wait_for_log("upload of 'kept.nc' abandoned after 6000 bytes: the connection ended")
    assert leftovers(ads_service.program_dir) == []
    assert (ads_service.program_dir / "kept.nc").read_bytes() == b"G1 X2\nM30\n"  # the old one


def test_a_write_beyond_the_store_limit_closes_the_handle_with_nothing_stored(
        tmp_path: Path) -> None:
    with limited_service(tmp_path, ads="127.0.0.1:0", program_max_bytes=100_000) as service:
        connection = RawAds(service)
        try:
            handle = _handle(connection, b"huge.nc", MODE_WRITE | PATH_GENERIC)
            chunk = b"G1 X1\n" * 10_000  # 60 000 bytes
            assert _call(connection, FWRITE, handle, 0, chunk) == (0, b"")
            code, message = _call(connection, FWRITE, handle, 0, chunk)
            assert code == 0x705  # beyond program_max_bytes
            assert _call(connection, FCLOSE, handle, 0, b"")[0] == 0x703  # gone with the upload
        finally:
            connection.close()
        assert leftovers(service.program_dir) == []
        assert not (service.program_dir / "huge.nc").exists()
        service.wait_for_log("upload of 'huge.nc' abandoned after 60000 bytes: "
                             "upload of 'huge.nc' reaches 120000 bytes")


def test_a_monitor_reads_files_and_may_not_write_or_delete_them(tmp_path: Path) -> None:
    config = tmp_path / "monitor.toml"
    config.write_text('[ads]\nloopback_role = "monitor"\n')
    with serving("--config", str(config), ads="127.0.0.1:0", keys=True) as service:
        (service.program_dir / "part.nc").write_bytes(b"G1 X1\nM30\n")
        connection = RawAds(service)
        try:
            handle = _handle(connection, b"part.nc", MODE_READ | PATH_GENERIC)
            assert _call(connection, FREAD, handle, 64, b"") == (0, b"G1 X1\nM30\n")
            assert _call(connection, FOPEN, MODE_WRITE | PATH_GENERIC, 4, b"new.nc\x00")[0] == 0x704
            assert _call(connection, FDELETE, PATH_GENERIC, 0, b"part.nc\x00")[0] == 0x704
        finally:
            connection.close()
        assert sorted(p.name for p in service.program_dir.iterdir()) == ["part.nc"]
