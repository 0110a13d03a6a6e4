"""Programs larger than a frame go in chunks: open, chunks in order, commit; landed whole
and atomically, or abandoned with a clear ADS error and nothing left behind."""

from __future__ import annotations

import hashlib
import struct
import subprocess
import sys
import time
import tracemalloc
from pathlib import Path

import pytest

from cnc_objects.clients import AdsError, Client
from cnc_objects.protocol.constants import PROGRAM_STORE_GROUP, CncPort
from cnc_objects.protocol.constants import ProgramStoreOffset as Op
from cnc_objects.testing import serving, start_service
from tests.limits.wire import limited_service
from tests.support.uploads import g1_program, leftovers, peak_rss_bytes, write_big_program

INVALIDSIZE, INVALIDDATA, NOMEMORY, INVALIDSTATE = 0x705, 0x706, 0x70A, 0x712








def raw(cnc: Client, offset: int, data: bytes) -> None:
    cnc.write_raw(CncPort.COM, PROGRAM_STORE_GROUP, offset, data)


def test_a_program_larger_than_a_frame_lands_whole_with_progress() -> None:
    program = g1_program(3_000_000)  # three times what one frame carries
    seen: list[tuple[int, int]] = []
    with serving() as service, Client(service.endpoint) as cnc:
        cnc.upload("cam.nc", program, lambda sent, total: seen.append((sent, total)))
        stored = service.program_dir / "cam.nc"
        assert stored.stat().st_size == len(program)
        assert hashlib.sha256(stored.read_bytes()).digest() == hashlib.sha256(program).digest()
        assert [(p.name, p.size_bytes) for p in cnc.programs()] == [("cam.nc", len(program))]
        assert seen[-1] == (len(program), len(program)) and len(seen) > 10
        assert [s for s, _ in seen] == sorted(s for s, _ in seen)
        assert leftovers(service.program_dir) == []


def test_a_file_uploads_a_chunk_at_a_time_without_lying_in_memory_whole(tmp_path: Path) -> None:
    program = g1_program(40_000_000)
    local = tmp_path / "cam.nc"
    local.write_bytes(program)
    seen: list[tuple[int, int]] = []
    with serving(program_dir=tmp_path / "programs") as service, \
            Client(service.endpoint) as cnc:
        tracemalloc.start()
        try:
            with local.open("rb") as file:
                cnc.upload("cam.nc", file, lambda got, total: seen.append((got, total)))
            peak_bytes = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
        assert seen[-1] == (len(program), len(program))
        assert peak_bytes < 4_000_000, peak_bytes  # a few chunks, not 40 MB
        stored = (service.program_dir / "cam.nc").read_bytes()
        assert hashlib.sha256(stored).digest() == hashlib.sha256(program).digest()
        assert leftovers(service.program_dir) == []


def test_a_program_larger_than_a_frame_downloads_whole_in_frames(tmp_path: Path) -> None:
    program = g1_program(2_500_000)  # three frames of FREAD
    seen: list[tuple[int, int]] = []
    with serving(program_dir=tmp_path / "programs") as service, \
            Client(service.endpoint) as cnc:
        (service.program_dir / "cam.nc").write_bytes(program)
        (service.program_dir / "small.nc").write_bytes(b"G1 X1\nM30\n")
        assert cnc.download("cam.nc", lambda got, total: seen.append((got, total))) == program
        assert seen == [(1_000_000, len(program)), (2_000_000, len(program)),
                        (len(program), len(program))]
        assert cnc.download("small.nc") == b"G1 X1\nM30\n"  # one frame, as before
        with pytest.raises(AdsError) as missing:
            cnc.download("none.nc")
        assert missing.value.code == 0x70C
        done = subprocess.run(
            [sys.executable, "-c", "from cnc_objects.clients.cli import main; main()",
             "--endpoint", service.endpoint, "download", "cam.nc", "-o", str(tmp_path / "got.nc")],
            capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stderr
        assert (tmp_path / "got.nc").read_bytes() == program


def test_a_chunk_out_of_order_or_a_wrong_total_abandons_the_upload() -> None:
    with serving() as service, Client(service.endpoint) as cnc:
        cnc.upload("p.nc", b"M30\n")
        raw(cnc, Op.UPLOAD_OPEN, b"p.nc\x00")
        raw(cnc, Op.UPLOAD_CHUNK, struct.pack("<Q", 0) + b"G1 X1\n")
        assert len(leftovers(service.program_dir)) == 1
        with pytest.raises(AdsError) as caught:
            raw(cnc, Op.UPLOAD_CHUNK, struct.pack("<Q", 100) + b"G1 X2\n")
        assert caught.value.code == INVALIDDATA and "expected byte 6" in str(caught.value)
        assert leftovers(service.program_dir) == []
        with pytest.raises(AdsError) as caught:  # abandoned: a chunk needs a new open
            raw(cnc, Op.UPLOAD_CHUNK, struct.pack("<Q", 6) + b"G1 X2\n")
        assert caught.value.code == INVALIDSTATE and "no upload open" in str(caught.value)
        raw(cnc, Op.UPLOAD_OPEN, b"p.nc\x00")
        raw(cnc, Op.UPLOAD_CHUNK, struct.pack("<Q", 0) + b"G1 X1\n")
        with pytest.raises(AdsError) as caught:
            raw(cnc, Op.UPLOAD_COMMIT, struct.pack("<Q", 7))
        assert caught.value.code == INVALIDDATA and "6 arrived" in str(caught.value)
        assert leftovers(service.program_dir) == []
        assert cnc.download("p.nc") == b"M30\n"  # the old version, untouched


def test_a_bad_name_is_refused_at_the_open() -> None:
    with serving() as service, Client(service.endpoint) as cnc:
        with pytest.raises(AdsError) as caught:
            raw(cnc, Op.UPLOAD_OPEN, b"../etc.nc\x00")
        assert caught.value.code == INVALIDDATA and "plain file name" in str(caught.value)
        assert leftovers(service.program_dir) == []


def test_an_upload_beyond_the_program_limit_is_abandoned(tmp_path: Path) -> None:
    with limited_service(tmp_path, program_max_bytes=2_000_000) as service, \
            Client(service.endpoint) as cnc:
        cnc.upload("p.nc", b"M30\n")
        with pytest.raises(AdsError) as caught:
            cnc.upload("p.nc", g1_program(2_500_000))
        assert caught.value.code == INVALIDSIZE and "at most 2000000" in str(caught.value)
        assert leftovers(service.program_dir) == []
        assert cnc.download("p.nc") == b"M30\n"
        cnc.upload("q.nc", g1_program(1_500_000))  # below the limit: in chunks, whole
        assert (service.program_dir / "q.nc").stat().st_size > 1_500_000


def test_an_upload_beyond_the_store_total_is_abandoned(tmp_path: Path) -> None:
    with limited_service(tmp_path, store_max_total_bytes=1_000_000) as service, \
            Client(service.endpoint) as cnc:
        cnc.upload("a.nc", g1_program(600_000))
        with pytest.raises(AdsError) as caught:
            cnc.upload("b.nc", g1_program(600_000))
        assert caught.value.code == NOMEMORY and "more than 1000000" in str(caught.value)
        assert leftovers(service.program_dir) == []
        assert [p.name for p in cnc.programs()] == ["a.nc"]


def test_a_connection_that_ends_mid_upload_leaves_nothing() -> None:
    with serving() as service:
        with Client(service.endpoint) as cnc:
            raw(cnc, Op.UPLOAD_OPEN, b"gone.nc\x00")
            raw(cnc, Op.UPLOAD_CHUNK, struct.pack("<Q", 0) + b"G1 X1\n" * 1000)
            assert len(leftovers(service.program_dir)) == 1
        service.wait_for_log("upload of 'gone.nc' abandoned after 6000 bytes: the connection ended")
        assert leftovers(service.program_dir) == []
        assert not (service.program_dir / "gone.nc").exists()


def test_a_service_killed_mid_upload_leaves_a_temporary_file_the_next_one_removes(
        tmp_path: Path) -> None:
    store = tmp_path / "programs"
    killed = start_service(program_dir=store)
    try:
        with Client(killed.endpoint) as cnc:
            raw(cnc, Op.UPLOAD_OPEN, b"cut.nc\x00")
            raw(cnc, Op.UPLOAD_CHUNK, struct.pack("<Q", 0) + b"G1 X1\n" * 1000)
            killed.process.kill()  # SIGKILL: no chance to abandon anything
            killed.process.wait(timeout=10)
    finally:
        killed.stop()
    assert len(leftovers(store)) == 1
    with serving(program_dir=store) as service:
        assert leftovers(store) == []
        assert "removed 1 unfinished upload(s) a stopped service left" in service.log_text
        assert not (store / "cut.nc").exists()




def test_a_200_mb_cam_program_lands_whole(tmp_path: Path) -> None:
    """The size CAM writes: 200 MB of G1 lines, made on the fly, land byte for byte; the
    service's memory does not grow with the program (chunks go to the file)."""
    local = tmp_path / "finish.nc"
    digest = write_big_program(local)
    program = local.read_bytes()
    with serving() as service, Client(service.endpoint) as cnc:
        before = peak_rss_bytes(service.process.pid)
        started = time.perf_counter()
        cnc.upload("finish.nc", program)
        elapsed_s = time.perf_counter() - started
        after = peak_rss_bytes(service.process.pid)
        stored = service.program_dir / "finish.nc"
        assert stored.stat().st_size == len(program) > 200_000_000
        with stored.open("rb") as f:
            assert hashlib.file_digest(f, "sha256").digest() == digest
        assert leftovers(service.program_dir) == []
        print(f"\n200 MB upload: {len(program) / elapsed_s / 1e6:.0f} MB/s, service peak RSS "
              f"{before / 1e6:.0f} -> {after / 1e6:.0f} MB")
        assert after - before < 50_000_000  # not the program's 200 MB
