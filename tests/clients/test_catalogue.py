"""The client's catalogue of objects: one browse per connection, whoever asks first.

A cold ``asyncio.gather`` of 500 reads on a fresh ``AsyncClient`` used to send 500
browses of the whole catalogue (one per read that found it missing), about 420 rate
tokens each (the default machine's 2 749 objects, 417 KiB of reply, one token a KiB).
The service here grants a client a bucket of 600 tokens refilled at one a second and a
mailbox of one request: one browse and the batched reads fit, a second browse already
does not, and the ones after it are refused ADS 0x502 (mailbox full).
"""

from __future__ import annotations

import asyncio
from pathlib import Path

from cnc_objects.clients.client import AsyncClient
from tests.limits.wire import limited_service

READS = 500
TIMEOUT_S = 60.0
BURST = 600  # one browse (about 420 tokens) and the reads; not two browses


async def test_a_cold_gather_of_500_reads_browses_the_catalogue_once(tmp_path: Path) -> None:
    with limited_service(tmp_path, requests_per_s_per_client=1.0, request_burst=BURST,
                         request_mailbox=1) as service:
        async with AsyncClient(service.endpoint, timeout_s=TIMEOUT_S) as fresh:
            async with AsyncClient(service.endpoint) as other:  # its own bucket
                names = [o.name for o in await other.browse("*") if "r" in o.access][:READS]
            values = await asyncio.wait_for(
                asyncio.gather(*(fresh.read(n) for n in names)), TIMEOUT_S)
            assert len(values) == READS
            assert await fresh.find(names[0].upper()) is not None  # cached, any case
            assert await fresh.find("ch1.no_such_object") is None

