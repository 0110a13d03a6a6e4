"""The syntax check and the traced dry run (``cnc plot``) of a big CAM program (issue 37).

    python -m bench.big_program_bench check 200   # cnc check of a 200 MB program
    python -m bench.big_program_bench plot 20     # cnc plot (PROD_TIME, traced) of 20 MB

Prints the wall time and the service's RSS before and at most while it runs (sampled
every 0.2 s). The program is ``tests/support/cam_programs.py`` (0.05 mm G1 steps in X Y Z),
written once to the temporary directory and kept there for the next run.
"""

from __future__ import annotations

import sys
import tempfile
import threading
import time
from pathlib import Path

from cnc_objects.clients import Client
from cnc_objects.testing import serving
from tests.support.cam_programs import write_cam_program
from tests.support.resources import rss_kib

_RSS_EVERY_S = 0.2


def measure(mode: str, size_mb: float) -> str:
    """One check (``mode`` "check") or traced dry run ("plot") of a program of
    ``size_mb`` MB: a line of figures."""
    size = int(size_mb * 1e6)
    path = Path(tempfile.gettempdir()) / f"cnc-bench-cam{size}.nc"
    if not path.exists():
        write_cam_program(path, size)
    with serving() as service, Client(service.endpoint, timeout_s=600) as c:
        with path.open("rb") as f:
            c.upload(path.name, f)
        pid = service.process.pid
        before = most = rss_kib(pid)
        done = threading.Event()

        def sample() -> None:
            nonlocal most
            while not done.wait(_RSS_EVERY_S):
                most = max(most, rss_kib(pid))

        threading.Thread(target=sample, daemon=True).start()
        started = time.perf_counter()
        if mode == "check":
            result = c.syntax_check(path.name, timeout_s=3600)
            what = f"{result.lines} lines, {len(result.errors)} errors"
        else:
            trace = c.trace_run(path.name, 1, 3600)
            what = f"{trace.program_time_s:.0f} s of machining, ended {trace.ended}"
        wall_s = time.perf_counter() - started
        done.set()
    return (f"{mode} of {size_mb:g} MB: {wall_s:.1f} s wall, {what}; service RSS "
            f"{before / 1024:.0f} -> max {most / 1024:.0f} MiB")


if __name__ == "__main__":
    print(measure(sys.argv[1], float(sys.argv[2])))
