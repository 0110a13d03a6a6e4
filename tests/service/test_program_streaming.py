"""A stored program runs and is checked as a stream: the service's memory does not grow
with the program, and errors far into a big program name the right line and column.

Two sizes of the same CAM-like program (``tests/support/cam_programs``) run on a real
service (virtual clock); the service's resident memory is read before START and once
the run is well past the first pages of the file. Held whole, the 40 MB program would
take about 200 MB more than the 4 MB one (its lines as Python strings).
"""

from __future__ import annotations

from pathlib import Path

from cnc_objects.clients import Client
from cnc_objects.testing import serving
from cnc_objects.testing.helpers import wait_for
from tests.support.cam_programs import write_cam_program
from tests.support.resources import rss_kib

SIZES_BYTES = (4_000_000, 40_000_000)
LINES_RUN = 30_000  # the run is this far (about 6 pages of 128 KiB) when RSS is read
GROWTH_MAX_KIB = 20_000  # what a run may add, whatever the size of its program


def rss_growth_kib(cnc: Client, pid: int, name: str) -> int:
    """RSS added by starting ``name`` and running it past ``LINES_RUN`` lines."""
    cnc.reset(1)
    before = rss_kib(pid)
    cnc.run_program(name)
    wait_for(cnc, "ch1.mc_active_line_r", lambda line: line > LINES_RUN, timeout_s=120)
    grown = rss_kib(pid) - before
    cnc.reset(1)
    return grown


def test_the_memory_of_a_run_does_not_grow_with_the_program(tmp_path: Path) -> None:
    with serving() as service, Client(service.endpoint, timeout_s=60) as cnc:
        growth = {}
        for size in SIZES_BYTES:
            local = tmp_path / f"cam{size}.nc"
            write_cam_program(local, size)
            cnc.upload(local.name, local.read_bytes())
            growth[size] = rss_growth_kib(cnc, service.process.pid, local.name)
        small, large = (growth[size] for size in SIZES_BYTES)
        assert large < GROWTH_MAX_KIB and large - small < GROWTH_MAX_KIB / 2, growth


def test_an_error_far_into_a_big_program_names_its_line_and_column(tmp_path: Path) -> None:
    local = tmp_path / "bad.nc"
    lines = write_cam_program(local, 6_000_000, last_line=b"N9 X1  Q7\nM30\n")
    with serving() as service, Client(service.endpoint, timeout_s=60) as cnc:
        cnc.upload(local.name, local.read_bytes())
        result = cnc.syntax_check(local.name, timeout_s=120)
        assert [(e.file, e.line, e.column) for e in result.errors] == [
            ("bad.nc", lines + 1, 8)]
