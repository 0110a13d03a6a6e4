"""A chunked program upload over AMS/TCP (frames built by hand, ``test_ads_raw``): it lands
whole, and a connection closed mid-upload leaves nothing in the store."""

from __future__ import annotations

import hashlib
import struct

from cnc_objects.testing import ServiceProcess
from tests.support.ads_raw import COM, WRITE, RawAds, write

STORE = 0x150000
OPEN, CHUNK, COMMIT = 5, 6, 7
CHUNK_BYTES = 256 * 1024


def leftovers(service: ServiceProcess) -> list[str]:
    return sorted(p.name for p in service.program_dir.iterdir() if p.name.startswith("."))


def test_a_program_of_three_frames_lands_whole_over_ads(
        ads: RawAds, ads_service: ServiceProcess) -> None:
    program = b"".join(b"N%d G1 X%d.5 Y1 F900\n" % (n, n % 400) for n in range(150_000))
    assert len(program) > 3_000_000
    assert ads.call(WRITE, write(STORE, OPEN, b"ads-big.nc\x00"), port=COM).result == 0
    for start in range(0, len(program), CHUNK_BYTES):
        chunk = struct.pack("<Q", start) + program[start:start + CHUNK_BYTES]
        assert ads.call(WRITE, write(STORE, CHUNK, chunk), port=COM).result == 0
    assert ads.call(WRITE, write(STORE, COMMIT, struct.pack("<Q", len(program))),
                    port=COM).result == 0
    stored = (ads_service.program_dir / "ads-big.nc").read_bytes()
    assert hashlib.sha256(stored).digest() == hashlib.sha256(program).digest()
    assert leftovers(ads_service) == []


def test_a_chunk_out_of_order_over_ads_is_0x706(ads: RawAds, ads_service: ServiceProcess) -> None:
    assert ads.call(WRITE, write(STORE, OPEN, b"ads-bad.nc\x00"), port=COM).result == 0
    reply = ads.call(WRITE, write(STORE, CHUNK, struct.pack("<Q", 9) + b"G1 X1\n"), port=COM)
    assert reply.result == 0x706
    assert leftovers(ads_service) == []


def test_an_ads_connection_closed_mid_upload_leaves_nothing(ads_service: ServiceProcess) -> None:
    connection = RawAds(ads_service)
    try:
        assert connection.call(WRITE, write(STORE, OPEN, b"ads-gone.nc\x00"), port=COM).result == 0
        chunk = struct.pack("<Q", 0) + b"G1 X1\n" * 1000
        assert connection.call(WRITE, write(STORE, CHUNK, chunk), port=COM).result == 0
        assert len(leftovers(ads_service)) == 1
    finally:
        connection.close()
    ads_service.wait_for_log(
        "upload of 'ads-gone.nc' abandoned after 6000 bytes: the connection ended")
    assert leftovers(ads_service) == []
    assert not (ads_service.program_dir / "ads-gone.nc").exists()
