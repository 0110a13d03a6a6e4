"""``[limits] send_hwm_messages``: a client that never reads its replies costs the service
bounded memory; the others are served on."""

from __future__ import annotations

import struct
from pathlib import Path

from cnc_objects.protocol.frames import WriteRequest
from cnc_objects.service.limits import LimitsConfig
from tests.limits.wire import (
    ERROR_TEXT,
    FEED_OVERRIDE_R,
    FEED_OVERRIDE_W,
    Raw,
    limited_service,
    next_id,
    read_frame,
    wait_until,
)
from tests.support.resources import rss_kib

READS = 100_000
#: What one queued reply of a 256-byte read costs the service (measured: about 270 bytes
#: for 10 000 replies), with room for the allocator.
REPLY_COST_BYTES = 400
DONE_TIMEOUT_S = 120.0


def test_a_client_that_never_reads_costs_bounded_memory(tmp_path: Path) -> None:
    hwm = LimitsConfig().send_hwm_messages  # the default
    bound_kib = hwm * REPLY_COST_BYTES // 1024
    # No rate limit here: every read is answered (and its reply queued or dropped).
    with limited_service(tmp_path, requests_per_s_per_client=0) as service:
        pid = service.process.pid
        with Raw(service.endpoint) as bystander, \
                Raw(service.endpoint, RCVHWM=1, RCVBUF=4096) as deaf:
            assert bystander.read(FEED_OVERRIDE_R, 2) == struct.pack("<H", 1000)
            rss_before_kib = rss_kib(pid)
            frame = read_frame(ERROR_TEXT, 256)  # a 256-byte string: replies of 270 bytes
            for _ in range(READS):
                deaf.sock.send(frame, copy=False)
            # Its last request changes what the bystander can see: once it shows, the
            # service has handled every read before it (one client's frames in order).
            deaf.send(WriteRequest(next_id(), *FEED_OVERRIDE_W, struct.pack("<H", 500)).encode())
            wait_until(lambda: bystander.read(FEED_OVERRIDE_R, 2) == struct.pack("<H", 500),
                       DONE_TIMEOUT_S, "the deaf client's requests handled")
            growth_kib = rss_kib(pid) - rss_before_kib
            print(f"\n{READS} reads of 256 bytes never received, send_hwm_messages {hwm}: "
                  f"service RSS {rss_before_kib} -> {rss_before_kib + growth_kib} KiB "
                  f"(+{growth_kib} KiB; bound {bound_kib} KiB)")
            assert growth_kib < bound_kib
            assert bystander.read(FEED_OVERRIDE_R, 2) == struct.pack("<H", 500)
        service.wait_for_log(r"replies to clients dropped; .*send_hwm_messages")
