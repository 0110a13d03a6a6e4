"""``AsyncClient`` batching (issue 30): the reads and writes of one event-loop turn go out
as ADS sum commands, transparently, against the real service.

``AsyncTransport.frames_sent`` counts the request frames handed to ZeroMQ; every other
figure is what the service answered."""

from __future__ import annotations

import asyncio
from typing import Any

import pytest

from cnc_objects.clients import AdsError, AsyncClient, NoReplyError
from cnc_objects.clients.batching import BATCH_ITEM_MAX_BYTES, BATCH_MAX_ITEMS
from tests.support.service import RunningService

GEO, COM = 551, 553
LINKS = [f"ch1.ax{k}.actual_link_to_physical_axis" for k in (1, 2, 3)]
OVERRIDE_W, OVERRIDE_R = "ch1.mc_command_feed_override_w", "ch1.mc_command_feed_override_r"
ACTIVE_R = "ch1.mc_active_feed_override_r"
NO_OBJECT = (COM, 0x120100, 0x7FFF, "UNS32")  # an address where nothing is


def frames(client: AsyncClient) -> int:
    return client._t.frames_sent  # type: ignore[union-attr]


async def test_a_gather_of_64_reads_is_one_frame(service: RunningService) -> None:
    async with AsyncClient(service.endpoint) as c:
        await c.read(LINKS[0])  # the catalog browsed
        before = frames(c)
        values = await asyncio.gather(*(c.read(LINKS[k % 3]) for k in range(64)))
        assert frames(c) - before == 1
    assert values == [1, 2, 3] * 21 + [1]


async def test_opting_out_sends_each_read_alone(service: RunningService) -> None:
    async with AsyncClient(service.endpoint, batch=False) as c:
        await c.read(LINKS[0])
        before = frames(c)
        values = await asyncio.gather(*(c.read(LINKS[k % 3]) for k in range(64)))
        assert frames(c) - before == 64
    assert values == [1, 2, 3] * 21 + [1]


async def test_64_writes_are_one_frame_and_applied_in_their_order(
        service: RunningService) -> None:
    async with AsyncClient(service.endpoint) as c:
        await c.read(OVERRIDE_R)
        before = frames(c)
        # the same object 64 times: only the order decides which value stays
        await asyncio.gather(*(c.write(OVERRIDE_W, 100 + k) for k in range(64)))
        assert frames(c) - before == 1
        assert await c.read(OVERRIDE_R) == 163
        await asyncio.gather(*(c.write(OVERRIDE_W, 900 - k) for k in range(64)))
        assert await c.read(OVERRIDE_R) == 837


async def test_a_failed_read_fails_alone_with_the_plain_reads_error(
        service: RunningService) -> None:
    async with AsyncClient(service.endpoint, batch=False) as plain:
        with pytest.raises(AdsError) as alone:
            await plain.read_address(*NO_OBJECT)
    async with AsyncClient(service.endpoint) as c:
        await c.read(LINKS[0])
        results = await asyncio.gather(
            c.read(LINKS[0]), c.read_address(*NO_OBJECT), c.read(LINKS[2]),
            return_exceptions=True)
    assert results[0] == 1 and results[2] == 3
    error: Any = results[1]
    assert isinstance(error, AdsError)
    assert (error.code, str(error)) == (alone.value.code, str(alone.value))


async def test_a_failed_write_fails_alone_with_its_code(service: RunningService) -> None:
    async with AsyncClient(service.endpoint) as c:
        await c.read(OVERRIDE_R)
        results = await asyncio.gather(
            c.write("ch1.mc_command_feed_override_w", 700),
            c.write("ch1.mc_command_feed_override_w", 1001),  # above 100 %: refused, 0x706
            c.write("ch1.ax1.link_state", 1),  # read-only: 0x704
            c.write("ch2.mc_command_feed_override_w", 300),
            return_exceptions=True)
        assert results[0] is None and results[3] is None
        assert [r.code for r in results[1:3]] == [0x706, 0x704]  # type: ignore[union-attr]
        assert "sum write" in str(results[1])
        assert await c.read_many([OVERRIDE_R, "ch2.mc_command_feed_override_r"]) == {
            OVERRIDE_R: 700, "ch2.mc_command_feed_override_r": 300}


async def test_mixed_reads_and_writes_keep_their_order(service: RunningService) -> None:
    async with AsyncClient(service.endpoint) as c:
        await c.write(OVERRIDE_W, 400)
        before = frames(c)
        results = await asyncio.gather(
            c.read(OVERRIDE_R), c.read(ACTIVE_R),  # a sum read: the value before the writes
            c.write(OVERRIDE_W, 500), c.write(OVERRIDE_W, 600),  # a sum write
            c.read(OVERRIDE_R),  # alone, after the writes
            c.read(LINKS[1]), c.read(LINKS[2]))  # another AMS port: another sum read
        assert frames(c) - before == 4
        assert results[:4] == [400, 400, None, None]
        # the snapshot may show neither write yet, or (seen under load) the first: a sum
        # write's items are applied one after another, as TwinCAT applies them
        assert results[4] in (400, 500, 600)
        assert results[5:] == [2, 3]
        assert await c.read(OVERRIDE_R) == 600


async def test_large_gathers_are_split_within_the_limits(service: RunningService) -> None:
    count = 2 * BATCH_MAX_ITEMS + 10
    async with AsyncClient(service.endpoint) as c:
        await c.read(LINKS[0])
        before = frames(c)
        values = await asyncio.gather(*(c.read(LINKS[k % 3]) for k in range(count)))
        assert frames(c) - before == 3
        assert values == [[1, 2, 3][k % 3] for k in range(count)]
        # a read larger than an item may be goes out alone, beside the batch
        before = frames(c)
        big, *links = await asyncio.gather(
            c.read_raw(GEO, 0x121301, 0x10018, BATCH_ITEM_MAX_BYTES + 1),
            c.read(LINKS[0]), c.read(LINKS[1]), return_exceptions=True)
        assert links == [1, 2]
        assert isinstance(big, AdsError)  # the service's answer to the plain read
        assert frames(c) - before == 2


async def test_a_batch_without_reply_times_out_each_request() -> None:
    async with AsyncClient("tcp://127.0.0.1:9", timeout_s=0.2) as c:  # nothing answers
        results = await asyncio.gather(*(c.read_address(GEO, 0x121301, 0x10018, "UNS32")
                                         for _ in range(8)), return_exceptions=True)
        assert frames(c) == 1
    assert all(isinstance(r, NoReplyError) and r.request == "READ" for r in results)


async def test_closing_fails_requests_not_yet_sent(service: RunningService) -> None:
    c = AsyncClient(service.endpoint)
    await c.__aenter__()
    reads = [asyncio.ensure_future(c.read_address(GEO, 0x121301, 0x10018, "UNS32"))
             for _ in range(4)]
    await asyncio.sleep(0)  # the reads are queued, the loop turn not yet over
    await c.__aexit__(None, None, None)
    results = await asyncio.wait_for(asyncio.gather(*reads, return_exceptions=True), 5)
    assert all(isinstance(r, AdsError) and r.code == 0x748 for r in results)
