"""The client API against a real service: the async and the blocking client, same tests.

Each test body runs twice, once through ``AsyncClient`` and once through ``Client``, via
the ``api`` fixture, which hands out an object whose methods are awaitable either way.
"""

from __future__ import annotations

import asyncio
import contextlib
import datetime as dt
import struct
from collections.abc import AsyncIterator
from typing import Any

import pytest

import cnc_objects.clients
from cnc_objects.clients import (
    AdsError,
    AdsTimeoutError,
    AsyncClient,
    Client,
    ClientValueError,
    NoReplyError,
)
from cnc_objects.clients.transport import EARLY_HANDLES, _Transport
from cnc_objects.objects.catalog_manual import MANUAL_ROWS
from cnc_objects.objects.templates import Scope
from cnc_objects.protocol.constants import AdsState
from cnc_objects.protocol.frames import Notification
from cnc_objects.protocol.frames import RawSample as FrameSample
from tests.support.service import RunningService

GEO, COM = 551, 553


class BlockingAsAsync:
    """Await-able facade over the blocking client, so one test body serves both."""

    def __init__(self, client: Client) -> None:
        self._client = client

    def __getattr__(self, name: str) -> Any:
        method = getattr(self._client, name)

        async def call(*args: Any, **kwargs: Any) -> Any:
            return method(*args, **kwargs)

        return call


@pytest.fixture(params=["async", "blocking"])
async def api(request: pytest.FixtureRequest, service: RunningService) -> AsyncIterator[Any]:
    """A connected client of a fresh service, async or blocking."""
    if request.param == "async":
        async with AsyncClient(service.endpoint, timeout_s=5) as client:
            yield client
    else:
        with Client(service.endpoint, timeout_s=5) as client:
            yield BlockingAsAsync(client)


async def test_info_names_device_and_state(api: Any) -> None:
    info = await api.info()
    assert info.name == "cnc-objects"
    assert info.version == "0.1.0"
    assert info.ads_state is AdsState.RUN


async def test_read_by_name_and_by_both_address_spellings(api: Any) -> None:
    assert await api.read("ch1.ax3.actual_link_to_physical_axis") == 3
    assert await api.read_address(GEO, 0x121301, 0x30017, "UNS16") == 3
    assert await api.read_address(GEO, 0x21301, 0x30017, "UNS16") == 3  # index-based
    # Channel 2 starts with its output suspended: requested but not linked.
    assert await api.read("ch2.ax1.requested_link_to_physical_axis") == 1
    assert await api.read("ch2.ax1.actual_link_to_physical_axis") == 0
    assert await api.read_address(GEO, 0x121302, 0x10018, "UNS32") == 1


async def test_names_are_case_insensitive(api: Any) -> None:
    assert await api.read("CH1.AX2.Actual_Link_To_Physical_Axis") == 2


async def test_write_is_applied_before_the_reply(api: Any) -> None:
    await api.write("ch1.mc_command_feed_override_w", 455)
    # No waiting: the reply came after the kernel applied the write.
    assert await api.read("ch1.mc_command_feed_override_r") == 455
    assert await api.read("ch1.mc_active_feed_override_r") == 455
    await api.write_address(COM, 0x20101, 0x09, "UNS16", 0x3E8)  # index-based group, hex
    assert await api.read_address(COM, 0x120101, 0x0C, "UNS16") == 1000


async def test_execution_mode_implemented_bits_are_accepted_others_refused(api: Any) -> None:
    await api.write("ch1.mc_command_execution_mode_w", 0x48)  # SYNCHK | MACHINE_LOCK
    assert await api.read("ch1.mc_command_execution_mode_r") == 0x48
    assert await api.read("gpCh[0].decoder_mc_control.execution_mode.request_r") == 0x48
    with pytest.raises(AdsError) as caught:
        await api.write("ch1.mc_command_execution_mode_w", 0x1)
    assert caught.value.code == 0x706
    assert "BLOCK_SEARCH" in str(caught.value)
    assert await api.read("ch1.mc_command_execution_mode_r") == 0x48  # nothing stored
    assert await api.read("ch1.mc_active_execution_mode_r") == 0  # from the next start
    await api.write("ch1.mc_command_execution_mode_w", 0)


async def test_error_names_code_and_reason(api: Any) -> None:
    with pytest.raises(AdsError) as caught:
        await api.write("ch1.ax1.link_state", 1)
    assert caught.value.code == 0x704
    assert str(caught.value) == "ADS 0x704 INVALIDACCESS: ch1.ax1.link_state is read-only"
    with pytest.raises(AdsError) as caught:
        await api.write("ch1.mc_command_feed_override_w", 1001)
    assert caught.value.code == 0x706
    assert str(caught.value).startswith("ADS 0x706 INVALIDDATA: feed override 100.1 %")
    with pytest.raises(AdsError) as caught:
        await api.read("ch9.nothing")
    assert caught.value.code == 0x710


async def test_value_of_wrong_type_is_refused_by_the_client(api: Any) -> None:
    # Refused before anything is sent: a ValueError, no ADS code (no device answered).
    with pytest.raises(ClientValueError) as caught:
        await api.write("ch1.mc_command_feed_override_w", "fast")
    assert not isinstance(caught.value, AdsError)
    assert str(caught.value) == "ch1.mc_command_feed_override_w: UNS16 takes an integer, not 'fast'"
    with pytest.raises(ClientValueError) as caught:
        await api.write("ch1.mc_command_feed_override_w", 70000)
    assert str(caught.value) == (
        "ch1.mc_command_feed_override_w: value 70000 out of range for UNS16 (0..65535)")
    with pytest.raises(ValueError, match="value -1 out of range for UNS16"):
        await api.write_address(COM, 0x120101, 9, "UNS16", -1)
    with pytest.raises(ClientValueError, match="FLOAT9"):
        await api.read_address(COM, 0x120101, 9, "FLOAT9")
    assert await api.read("ch1.mc_command_feed_override_r") == 1000  # nothing was written


async def test_an_unknown_name_suggests_the_nearest(api: Any) -> None:
    with pytest.raises(AdsError) as caught:
        await api.read("ch1.mc_command_feed_overide_w")
    assert caught.value.code == 0x710
    assert str(caught.value) == (
        "ADS 0x710 SYMBOLNOTFOUND: no object 'ch1.mc_command_feed_overide_w'; did you mean "
        "ch1.mc_command_feed_override_w, ch2.mc_command_feed_override_w or "
        "ch1.mc_command_feed_override_r?")
    with pytest.raises(AdsError) as caught:
        await api.read("zzzz")
    assert str(caught.value) == "ADS 0x710 SYMBOLNOTFOUND: no object 'zzzz'"  # none near


async def test_read_many_in_one_sum_read(api: Any) -> None:
    names = [
        "ch1.ax1.link_state",
        "ch2.ax1.link_state",
        "cnc_cycle_time_r",
        "ch1.dist_prog_start",
        "cnc_version_r",
    ]
    values = await api.read_many(names)
    assert values == {
        "ch1.ax1.link_state": 0,
        "ch2.ax1.link_state": 1,
        "cnc_cycle_time_r": 1000,
        "ch1.dist_prog_start": 0.0,
        "cnc_version_r": "cnc-objects 0.1.0",
    }
    assert await api.read_many(names) == values  # second call: handles are cached
    # A command object reads back its last written value: a list that holds one reads.
    both = await api.read_many(["ch1.ax1.link_state", "ch1.mc_command_feed_override_w"])
    assert set(both) == {"ch1.ax1.link_state", "ch1.mc_command_feed_override_w"}
    with pytest.raises(AdsError) as caught:
        await api.read_many(["ch1.ax1.link_state", "ch1.no_such_object"])
    assert caught.value.code == 0x710


async def test_browse_describes_objects(api: Any) -> None:
    found = {o.name: o for o in await api.browse("ch1.ax1.*")}
    assert set(found) == {
        "ch1.ax1.requested_link_to_physical_axis",
        "ch1.ax1.actual_link_to_physical_axis",
        "ch1.ax1.link_state",
        "ch1.ax1.command_position_acs",
        "ch1.ax1.logical_axis_number",
        "ch1.ax1.axis_name",
        "ch1.ax1.axis_type",
        "ch1.ax1.position_offset",
        "ch1.ax1.vel_max",
        "ch1.ax1.acc_max",
        "ch1.ax1.vel_jump_max",
        *(f"ch1.ax1.{row.element}" for row in MANUAL_ROWS if row.scope == Scope.CHANNEL_AXIS),
        # tools and work offsets: positions in workpiece coordinates, zero offsets
        "ch1.ax1.command_position_pcs",
        "ch1.ax1.actual_position_pcs",
        "ch1.ax1.distance_to_go_pcs",
        *(f"ch1.ax1.np_grp[{group}].v" for group in range(1, 10)),
    }
    link = found["ch1.ax1.link_state"]
    assert (link.port, link.group, link.offset, link.type, link.length, link.access) == (
        GEO, 0x121301, 0x10018, "UNS32", 4, "r",
    )
    assert "waiting for acknowledgement" in link.description
    everything = await api.browse()
    assert len(everything) == len({o.name for o in everything}) > 40
    assert await api.browse("no.such.*") == []


async def test_com_directory_lists_mc_objects(api: Any) -> None:
    count = struct.unpack("<I", await api.read_raw(COM, 0x130101, 0, 4))[0]
    raw = await api.read_raw(COM, 0x130101, 1, 84 * count)
    names = {}
    for k in range(count):
        ident, size, writable, _, group, offset = struct.unpack_from("<IIHHII", raw, 84 * k)
        name = raw[84 * k + 20 : 84 * k + 52].split(b"\0")[0].decode()
        iec = raw[84 * k + 52 : 84 * k + 84].split(b"\0")[0].decode()
        assert ident == k + 1
        names[name] = (size, writable, group, offset, iec)
    assert names["mc_command_execution_mode_w"] == (4, 1, 0x120101, 0x3F, "DINT")
    assert names["mc_active_feed_override_r"] == (2, 0, 0x120101, 0x0C, "UINT")
    assert "cnc_tick_counter_r" in names  # platform data listed under channel 1
    # Channel 2's directory lists its own objects, not the platform's.
    count2 = struct.unpack("<I", await api.read_raw(COM, 0x130102, 0, 4))[0]
    assert 0 < count2 < count


async def test_write_control_stop_refuses_writes_until_run(api: Any) -> None:
    await api.write_control(AdsState.STOP)
    assert (await api.read_state())[0] is AdsState.STOP
    assert await api.read("cnc_kernel_running_r") is False
    with pytest.raises(AdsError) as caught:
        await api.write("ch1.mc_command_feed_override_w", 100)
    assert caught.value.code == 0x707
    assert await api.read("ch1.mc_command_feed_override_r") == 1000  # reads still served
    await api.write_control(AdsState.RUN)
    await api.write("ch1.mc_command_feed_override_w", 100)
    assert await api.read("ch1.mc_active_feed_override_r") == 100


async def test_write_control_takes_state_names(api: Any) -> None:
    await api.write_control("stop")
    assert (await api.read_state())[0] is cnc_objects.clients.AdsState.STOP
    await api.write_control(" Run ")
    assert (await api.read_state())[0] is AdsState.RUN
    with pytest.raises(ClientValueError) as caught:
        await api.write_control("STOPP")
    assert str(caught.value).startswith(
        "unknown ADS state 'STOPP'; the ADS states are INVALID, IDLE, RESET, INIT, START, RUN, "
        "STOP,")
    assert str(caught.value).endswith("(the service takes RUN, STOP and RESET)")
    assert (await api.read_state())[0] is AdsState.RUN


def test_the_package_exports_what_users_need() -> None:
    exported = cnc_objects.clients.__all__
    for name in ("AdsState", "AdsReturnCode", "ClientValueError", "NoReplyError",
                 "ExecutionMode", "DEFAULT_ENDPOINT", "Client", "AsyncClient"):
        assert name in exported and hasattr(cnc_objects.clients, name), name
    assert cnc_objects.clients.describe_execution_mode(0x48) == "SYNCHK|MACHINE_LOCK"
    assert cnc_objects.clients.describe_execution_mode(0) == "standard"


async def test_write_control_reset_restores_the_configuration(api: Any) -> None:
    await api.write("ch1.mc_command_feed_override_w", 250)
    await api.write_control(AdsState.RESET)
    assert await api.read("ch1.mc_command_feed_override_r") == 1000
    assert (await api.read_state())[0] is AdsState.RUN
    with pytest.raises(AdsError) as caught:
        await api.write_control(AdsState.CONFIG)
    assert caught.value.code == 0x706


async def test_kernel_cycles_advance(api: Any) -> None:
    first = await api.read("cnc_tick_counter_r")
    # A write is applied at a cycle start, so the counter has moved once it is acknowledged.
    await api.write("ch1.mc_command_feed_override_w", 999)
    assert await api.read("cnc_tick_counter_r") > first
    assert await api.read("cnc_kernel_time_r") > 0


# --------------------------------------------------------------------------- subscriptions


async def test_subscribe_on_change_sends_current_value_then_changes(service: RunningService) -> None:
    async with AsyncClient(service.endpoint) as c:
        samples = c.subscribe("ch1.mc_active_feed_override_r")
        async with contextlib.aclosing(samples):
            first = await anext(samples)
            assert (first.value, first.sequence) == (1000, 1)
            await c.write("ch1.mc_command_feed_override_w", 300)
            second = await asyncio.wait_for(anext(samples), 5)
            assert (second.value, second.sequence) == (300, 2)
            assert second.timestamp >= first.timestamp
            assert second.timestamp.tzinfo is dt.UTC


async def test_subscribe_cyclic_samples_on_the_kernel_time_grid(service: RunningService) -> None:
    async with AsyncClient(service.endpoint) as c:
        samples = c.subscribe("cnc_tick_counter_r", on_change=False, cycle_ms=10)
        async with contextlib.aclosing(samples):
            got = [await asyncio.wait_for(anext(samples), 5) for _ in range(4)]
    ticks = [s.value for s in got]
    assert [s.sequence for s in got] == [1, 2, 3, 4]
    assert ticks == sorted(ticks)
    assert all(t % 10 == 0 for t in ticks[1:])  # later samples fall on 10-cycle marks
    # Timestamps are the wall-clock times of the cycles (not kernel time): later cycles,
    # later stamps (tests/e2e/test_values_over_the_wire.py checks them against the wall).
    stamps = [s.timestamp for s in got]
    assert stamps == sorted(stamps) and len(set(stamps)) == len(stamps)


async def test_many_subscriptions_opened_at_once_all_get_their_first_sample(
    service: RunningService,
) -> None:
    """Opened together, the first samples of many subscriptions overtake the replies that
    name their handles; every one must still reach its subscriber (an MQTT bridge opens
    a hundred and more at start)."""
    async with AsyncClient(service.endpoint) as c:
        names = [o.name for o in await c.browse("*")
                 if "r" in o.access.lower() and not o.type.startswith("STRING")][:300]
        assert len(names) == 300

        async def first(name: str) -> object:
            samples = c.subscribe(name)
            async with contextlib.aclosing(samples):
                return (await anext(samples)).name

        got = await asyncio.wait_for(asyncio.gather(*(first(n) for n in names)), 30)
    assert list(got) == names


def test_early_samples_of_many_handles_wait_for_their_subscriber() -> None:
    """Samples routed before their handle is claimed (the reply not yet processed) are
    kept for hundreds of handles, not only the first 64; the oldest unclaimed ones (of
    subscriptions deleted meanwhile) make room."""
    transport = _Transport("tcp://127.0.0.1:9", 1.0)
    handles = range(1, 501)
    transport._route(Notification(0, tuple(FrameSample(h, 1, 0, b"x") for h in handles)))
    for h in handles:
        transport.open_samples(h)
        assert [s.handle for s in transport._samples[h]] == [h]
    stale = range(10_000, 10_000 + 2 * EARLY_HANDLES)
    transport._route(Notification(0, tuple(FrameSample(h, 1, 0, b"x") for h in stale)))
    assert len(transport._early) == EARLY_HANDLES  # bounded
    transport.open_samples(stale[-1])  # the newest early handle is still there
    assert len(transport._samples[stale[-1]]) == 1


def test_blocking_subscribe_deletes_its_notification_on_close(service: RunningService) -> None:
    with Client(service.endpoint) as c:
        samples = c.subscribe("ch1.ax1.link_state")
        assert next(samples).value == 0
        samples.close()  # deletes the notification on the service
        # The service answers further requests on the same connection.
        assert c.read("ch1.ax1.link_state") == 0


async def test_timeout_raises_the_library_error() -> None:
    # Nothing listens on this endpoint (port 9 is discard; ZeroMQ just never connects).
    async with AsyncClient("tcp://127.0.0.1:9", timeout_s=0.2) as c:
        with pytest.raises(AdsTimeoutError) as caught:
            await c.read_address(GEO, 0x121301, 0x10018, "UNS32")
    assert caught.value.code == 0x745
    with Client("tcp://127.0.0.1:9", timeout_s=0.2) as c:
        with pytest.raises(AdsTimeoutError):
            c.info()


@pytest.mark.parametrize("kind", ["async", "blocking"])
async def test_a_read_without_reply_names_the_read_not_its_browse(kind: str) -> None:
    endpoint = "tcp://127.0.0.1:9"  # nothing answers
    if kind == "async":
        async with AsyncClient(endpoint, timeout_s=0.2) as c:
            with pytest.raises(NoReplyError) as caught:
                await c.read("ch1.mc_active_state_r")
    else:
        with Client(endpoint, timeout_s=0.2) as c:
            with pytest.raises(NoReplyError) as caught:
                c.read_many(["a", "b", "c", "d", "e"])
    expected = "READ ch1.mc_active_state_r" if kind == "async" else "READ a, b, c and 2 more"
    assert caught.value.request == expected
    assert str(caught.value) == (f"ADS 0x745 SYNCTIMEOUT: no reply to {expected} within 0.2 s "
                                 f"from {endpoint} (is cnc-service running?)")


async def test_a_subscription_without_reply_names_the_subscription() -> None:
    endpoint = "tcp://127.0.0.1:9"  # nothing answers
    async with AsyncClient(endpoint, timeout_s=0.2) as c:
        with pytest.raises(NoReplyError) as caught:
            async for _sample in c.subscribe("ch1.mc_active_state_r"):
                break
    assert caught.value.request == "SUBSCRIBE ch1.mc_active_state_r"


async def test_many_requests_in_flight_are_matched_by_invoke_id(service: RunningService) -> None:
    async with AsyncClient(service.endpoint) as c:
        names = ["ch1.ax1.actual_link_to_physical_axis", "ch1.ax2.actual_link_to_physical_axis",
                 "ch1.ax3.actual_link_to_physical_axis"] * 100
        values = await asyncio.gather(*(c.read(n) for n in names))
    assert values == [1, 2, 3] * 100


async def test_a_program_larger_than_a_frame_is_sent_in_chunks(api: Any) -> None:
    await api.upload("big.nc", b"G1 X1 F100\n" * 100_000)  # 1.1 MB: more than a frame
    assert ("big.nc", 1_100_000) in [(p.name, p.size_bytes) for p in await api.programs()]
