"""``cnc upload`` (and run/check/plot of a local file) read a program a chunk at a time:
the client's memory does not grow with the program."""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from pathlib import Path

from cnc_objects.clients import Client
from cnc_objects.testing import serving
from tests.support.cam_programs import write_cam_program
from tests.support.service import ROOT

# ``cnc`` as a user runs it, telling its peak resident memory (KiB) on stderr at exit
_CNC_WITH_PEAK = (
    "import atexit, resource, sys\n"
    "atexit.register(lambda: print('PEAK_KIB', resource.getrusage(resource.RUSAGE_SELF)"
    ".ru_maxrss, file=sys.stderr))\n"
    "from cnc_objects.clients.cli import main\n"
    "main()\n"
)


def upload_peak_kib(endpoint: str, path: Path) -> int:
    """Peak RSS of ``cnc upload path``."""
    result = subprocess.run(
        [sys.executable, "-c", _CNC_WITH_PEAK, "--endpoint", endpoint, "upload", str(path)],
        cwd=ROOT, capture_output=True, text=True, timeout=120, env=dict(os.environ),
    )
    assert result.returncode == 0, result.stderr
    assert f"uploaded {path.name} ({path.stat().st_size} bytes)" in result.stdout
    return int(result.stderr.rsplit("PEAK_KIB", 1)[1].split()[0])


def test_cnc_upload_reads_a_big_program_a_chunk_at_a_time(tmp_path: Path) -> None:
    small, large = tmp_path / "small.nc", tmp_path / "large.nc"
    write_cam_program(small, 2_000_000)
    write_cam_program(large, 40_000_000)
    with serving() as service, Client(service.endpoint) as cnc:
        small_kib = upload_peak_kib(service.endpoint, small)
        large_kib = upload_peak_kib(service.endpoint, large)
        stored = service.program_dir / "large.nc"
        with stored.open("rb") as got, large.open("rb") as sent:
            assert hashlib.file_digest(got, "sha256").digest() == \
                hashlib.file_digest(sent, "sha256").digest()
        assert [p.size_bytes for p in cnc.programs() if p.name == "large.nc"] == [
            large.stat().st_size]
    # held whole, the 40 MB program would add 40 MB; read a chunk at a time, nothing
    print(f"\ncnc upload peak RSS: {small_kib} KiB (2 MB), {large_kib} KiB (40 MB)")
    assert large_kib - small_kib < 8_000, (small_kib, large_kib)
