"""A window of a stored program's lines (READ_LINES), read by the service without reading
the program, and an upload whose announced size the limits refuse at the open."""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from cnc_objects.clients import AdsError, Client
from cnc_objects.protocol.constants import PROGRAM_STORE_GROUP, CncPort
from cnc_objects.protocol.constants import ProgramStoreOffset as Op
from cnc_objects.service.storage import program_line_index
from cnc_objects.testing import serving
from tests.limits.wire import limited_service
from tests.support.uploads import g1_program, leftovers

INVALIDSIZE, INVALIDDATA, NOTFOUND, NOMEMORY = 0x705, 0x706, 0x70C, 0x70A


def expected_lines(program: bytes) -> list[str]:
    return program.decode().splitlines()


def test_windows_of_a_program_larger_than_a_frame_are_its_lines() -> None:
    program = g1_program(3_000_000)  # three index blocks, more than one frame
    lines = expected_lines(program)
    with serving() as service, Client(service.endpoint) as cnc:
        cnc.upload("cam.nc", program)
        for first in (1, 2, 17_000, len(lines) - 50, len(lines)):
            window = cnc.program_lines("cam.nc", first, 100)
            assert window.total_lines == len(lines)
            assert window.lines == lines[first - 1:first - 1 + 100], first
        beyond = cnc.program_lines("cam.nc", len(lines) + 1, 10)
        assert (beyond.total_lines, beyond.lines) == (len(lines), [])


def test_line_ends_and_a_last_line_without_newline() -> None:
    with serving() as service, Client(service.endpoint) as cnc:
        cnc.upload("crlf.nc", b"N10 G1 X1\r\nN20 G1 X2\r\n\r\nN30 M30")
        window = cnc.program_lines("crlf.nc", 2, 10)
        assert (window.total_lines, window.lines) == (4, ["N20 G1 X2", "", "N30 M30"])
        cnc.upload("empty.nc", b"")
        assert cnc.program_lines("empty.nc", 1, 10).total_lines == 0


def test_a_window_asks_for_whole_lines_of_a_stored_program() -> None:
    with serving() as service, Client(service.endpoint) as cnc:
        with pytest.raises(AdsError) as caught:
            cnc.program_lines("none.nc", 1, 10)
        assert caught.value.code == NOTFOUND and "no program 'none.nc'" in str(caught.value)
        with pytest.raises(AdsError) as caught:
            cnc.program_lines("../etc.nc", 1, 10)
        assert caught.value.code == INVALIDDATA and "plain file name" in str(caught.value)
        cnc.upload("p.nc", b"M30\n")
        for first, count in ((0, 10), (1, 0), (1, 10_001)):
            with pytest.raises(AdsError) as caught:
                cnc.read_write_raw(CncPort.COM, PROGRAM_STORE_GROUP, Op.READ_LINES,
                                   struct.pack("<QI", first, count) + b"p.nc\x00", 4096)
            assert caught.value.code == INVALIDDATA
        with pytest.raises(AdsError) as caught:
            cnc.read_write_raw(CncPort.COM, PROGRAM_STORE_GROUP, Op.READ_LINES,
                               struct.pack("<QI", 1, 1) + b"p.nc\x00", 12)
        assert caught.value.code == INVALIDSIZE


def test_a_long_line_is_cut_to_the_room_and_a_replaced_program_reindexed() -> None:
    with serving() as service, Client(service.endpoint) as cnc:
        cnc.upload("long.nc", b"(" + b"x" * 300_000 + b")\nM30\n")
        window = cnc.program_lines("long.nc", 1, 2)  # 256 KiB of room: the first line cut
        assert window.total_lines == 2 and len(window.lines) == 1
        assert window.lines[0].startswith("(xxx") and len(window.lines[0]) < 300_000
        assert cnc.program_lines("long.nc", 2, 5).lines == ["M30"]
        cnc.upload("long.nc", b"N1\nN2\nN3\n")  # a new version: a new index
        assert cnc.program_lines("long.nc", 2, 5).lines == ["N2", "N3"]


def test_an_announced_size_over_the_limits_is_refused_at_the_open(tmp_path: Path) -> None:
    with limited_service(tmp_path, program_max_bytes=2_000_000,
                         store_max_total_bytes=3_000_000) as service, \
            Client(service.endpoint) as cnc:
        open_with = (lambda size: cnc.write_raw(CncPort.COM, PROGRAM_STORE_GROUP, Op.UPLOAD_OPEN,
                                                b"big.nc\x00" + struct.pack("<Q", size)))
        with pytest.raises(AdsError) as caught:
            open_with(2_000_001)
        assert caught.value.code == INVALIDSIZE
        assert "at most 2000000 in one program ([limits] program_max_bytes)" in str(caught.value)
        cnc.upload("a.nc", g1_program(1_500_000))
        with pytest.raises(AdsError) as caught:
            open_with(1_900_000)
        assert caught.value.code == NOMEMORY and "delete some programs" in str(caught.value)
        assert leftovers(service.program_dir) == []
        open_with(1_000_000)  # within both: the upload is open
        assert len(leftovers(service.program_dir)) == 1


def test_the_index_has_one_entry_per_block(tmp_path: Path) -> None:
    path = tmp_path / "p.nc"
    path.write_bytes(b"N1\n" * 1_000_000)  # 3 MB: three blocks of a MiB
    index = program_line_index.build_index(path)
    assert index.total_lines == 1_000_000
    assert index.lines_before == (0, (1 << 20) // 3, (2 << 20) // 3)
    counter = program_line_index.LineCounter()  # what a chunked upload counts as it comes
    data = path.read_bytes() + b"M30"  # a last line without its newline
    for start in range(0, len(data), 262_151):  # pieces across the blocks' bounds
        counter.feed(data[start:start + 262_151])
    counted = counter.index(index.version)
    assert (counted.total_lines, counted.lines_before) == (1_000_001, index.lines_before)
