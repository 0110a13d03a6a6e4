"""A browse reply leaves the GIL to the cycle thread while it is encoded (issue 37).

The whole catalogue packed in one msgpack call held the GIL for 1.5-4 ms, and the
realtime cycle waited as long (one overrun per browse, docs/kernel.md "What delays the
realtime cycle"). ``ZmqServer.ok`` now packs a browse's rows one by one: the same bytes,
and between two rows a thread that asks for the GIL gets it.
"""

from __future__ import annotations

import sys
import threading
import time

import msgpack

from cnc_objects.objects.catalog import ChannelLayout, MachineLayout, build_objects
from cnc_objects.protocol.constants import AdsCommand, CncPort
from cnc_objects.protocol.frames import BrowseRequest
from cnc_objects.service.server import ZmqServer

#: The bench machine's shape: three channels of six axes (2 500 catalogue objects).
LAYOUT = MachineLayout(tuple(ChannelLayout(c, 6) for c in (1, 2, 3)), (1, 2, 3, 4, 5, 6))
RAN_S = 10e-6  # the encoding thread's CPU time between two steps of the other: it ran
HANDOFFS_MIN = 5  # times the GIL went back and forth during one encoding


def _handoffs(rows: list[list[object]], request: BrowseRequest) -> tuple[int, bytes]:
    """How many times another thread got the GIL back from this one while one browse reply
    was encoded (the most over several tries: the machine may be busy), and the frame.

    The other thread steps in a loop; where this thread's CPU time grew between two of
    its steps, this thread had the GIL in between (its CPU time does not grow while the
    other is preempted by the OS: then neither runs)."""
    handoffs: list[float] = []
    stop = threading.Event()
    encoder_cpu = time.pthread_getcpuclockid(threading.get_ident())

    def other() -> None:  # stands for the cycle thread: runs whenever it has the GIL
        last_cpu = time.clock_gettime(encoder_cpu)
        while not stop.is_set():
            cpu = time.clock_gettime(encoder_cpu)
            if cpu - last_cpu > RAN_S:
                handoffs.append(time.perf_counter())
            last_cpu = cpu

    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-4)  # the service's interval under SCHED_FIFO
    thread = threading.Thread(target=other, daemon=True)
    thread.start()
    best, frame = 0, b""
    try:
        for _ in range(40):
            start = time.perf_counter()
            frame = ZmqServer.ok((), request, list(rows))  # a new list: packed again
            end = time.perf_counter()
            best = max(best, sum(1 for t in list(handoffs) if start < t < end))
            if best >= HANDOFFS_MIN:
                break
    finally:
        stop.set()
        thread.join()
        sys.setswitchinterval(interval)
    return best, frame


def test_a_browse_of_the_catalogue_lets_other_threads_run_and_is_the_same_frame() -> None:
    # eight such catalogues (20 000 rows, 15 ms of packing): long enough that a busy
    # machine still runs the other thread several times meanwhile
    rows = [obj.describe() for obj in build_objects(LAYOUT)] * 8
    assert len(rows) > 20_000
    request = BrowseRequest(7, CncPort.COM, "*")
    handoffs, frame = _handoffs(rows, request)
    assert frame == msgpack.packb([7, AdsCommand.BROWSE, 0, rows], use_bin_type=True)
    assert handoffs >= HANDOFFS_MIN, (
        f"the other thread got the GIL {handoffs} times while the catalogue was encoded")
