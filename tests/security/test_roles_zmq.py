"""Roles over ZeroMQ with CURVE: a real service started with keys, the Python clients
with a monitor, an operator and an admin key (``start_service(keys=True)``).

monitor reads, browses and subscribes; operator also writes objects and runs programs;
admin also uploads and deletes programs. A request beyond the role gets ADS 0x704 with a
message naming the role, and the connection stays usable.
"""

from __future__ import annotations

import asyncio
import struct

import pytest

from cnc_objects.clients import AdsError, AsyncClient, Client
from cnc_objects.protocol import sum as sums
from cnc_objects.protocol.constants import ReservedIndexGroup as RIG
from cnc_objects.testing import ServiceProcess, run_program, wait_for

COM = 553
CH1_COM, CH2_COM = 0x120101, 0x120102
FEED_W, FEED_R = "ch1.mc_command_feed_override_w", "ch1.mc_command_feed_override_r"
PROGRAM = b"N10 G01 X1 F6000\nN20 G01 X0\nN30 M30\n"
INVALIDACCESS = 0x704


def client(service: ServiceProcess, role: str) -> Client:
    assert service.keys is not None
    return Client(service.endpoint, key_file=service.keys.client(role))


def test_monitor_reads_browses_and_subscribes(keyed: ServiceProcess) -> None:
    with client(keyed, "monitor") as c:
        assert c.info().name == "cnc-objects"
        assert [o.name for o in c.browse("ch1.mc_command_feed_override_*")] == [FEED_W, FEED_R]
        assert isinstance(c.read(FEED_R), int)
        assert set(c.read_many([FEED_R, "ch2.mc_command_feed_override_r"])) == {
            FEED_R, "ch2.mc_command_feed_override_r"}
        first = next(iter(c.subscribe(FEED_R)))
        assert first.name == FEED_R and isinstance(first.value, int)
        assert isinstance(c.programs(), list)


def test_monitor_write_is_refused_naming_the_role_and_the_connection_stays(
    keyed: ServiceProcess,
) -> None:
    with client(keyed, "monitor") as c:
        before = c.read(FEED_R)
        with pytest.raises(AdsError) as refused:
            c.write(FEED_W, 10 if before != 10 else 20)
        assert refused.value.code == INVALIDACCESS
        assert str(refused.value) == (
            f"ADS 0x704 INVALIDACCESS: role monitor may not write {FEED_W}; "
            "operator or admin may")
        assert c.read(FEED_R) == before  # nothing written, and the same connection answers
        with pytest.raises(AdsError, match="role monitor may not command the ADS state"):
            c.write_control("RESET")
        with pytest.raises(AdsError, match="role monitor may not write ch1.mc_command_program"):
            c.run_program("any.nc")
        with pytest.raises(AdsError, match=r"role monitor may not change the program store "
                                           r"\(upload, delete\); admin may$"):
            c.upload("monitor.nc", PROGRAM)
        assert "monitor.nc" not in [p.name for p in c.programs()]


def test_monitor_may_use_handles_but_not_write_through_them(keyed: ServiceProcess) -> None:
    name = FEED_W.encode() + b"\x00"
    with client(keyed, "monitor") as c:
        handle = struct.unpack("<I", c.read_write_raw(COM, RIG.SYM_HANDLE_BY_NAME, 0, name, 4))[0]
        with pytest.raises(AdsError, match=f"role monitor may not write {FEED_W};") as refused:
            c.write_raw(COM, RIG.SYM_VALUE_BY_HANDLE, handle, struct.pack("<H", 1))
        assert refused.value.code == INVALIDACCESS
        c.write_raw(COM, RIG.SYM_RELEASE_HANDLE, 0, struct.pack("<I", handle))  # changes nothing


def _sum_write(c: Client, values: list[int]) -> list[int]:
    items = [sums.SumItem(group, 0x09, data=struct.pack("<H", v))
             for group, v in zip((CH1_COM, CH2_COM), values)]
    data, read_length = sums.encode_sum_write(items)
    reply = c.read_write_raw(COM, RIG.SUM_WRITE, len(items), data, read_length)
    return sums.decode_codes(len(items), reply)


def test_sum_write_of_a_monitor_is_refused_in_every_slot(keyed: ServiceProcess) -> None:
    with client(keyed, "monitor") as monitor, client(keyed, "operator") as operator:
        assert _sum_write(operator, [111, 222]) == [0, 0]
        assert _sum_write(monitor, [333, 444]) == [INVALIDACCESS, INVALIDACCESS]
        assert monitor.read_many([FEED_R, "ch2.mc_command_feed_override_r"]) == {
            FEED_R: 111, "ch2.mc_command_feed_override_r": 222}


def test_operator_writes_and_runs_programs_but_not_the_store(keyed: ServiceProcess) -> None:
    with client(keyed, "admin") as admin:
        admin.upload("operator-run.nc", PROGRAM)
    with client(keyed, "operator") as c:
        c.write(FEED_W, 750)
        assert c.read(FEED_R) == 750
        assert wait_for(c, FEED_R, 750) == 750  # its second connection has the keys too
        c.write(FEED_W, 1000)
        assert run_program(c, "operator-run.nc").state == "READY"
        assert c.download("operator-run.nc") == PROGRAM
        with pytest.raises(AdsError, match="role operator may not change the program store"):
            c.upload("operator.nc", PROGRAM)
        with pytest.raises(AdsError, match="; admin may$") as refused:
            c.delete_program("operator-run.nc")
        assert refused.value.code == INVALIDACCESS
        assert "operator-run.nc" in [p.name for p in c.programs()]


def test_admin_uploads_and_deletes(keyed: ServiceProcess) -> None:
    with client(keyed, "admin") as c:
        c.upload("admin.nc", PROGRAM)
        assert c.download("admin.nc") == PROGRAM
        c.delete_program("admin.nc")
        assert "admin.nc" not in [p.name for p in c.programs()]
        c.write(FEED_W, 1000)


def test_async_client_roles(keyed: ServiceProcess) -> None:
    assert keyed.keys is not None

    async def main() -> None:
        monitor = AsyncClient(keyed.endpoint, key_file=keyed.keys.client("monitor"),
                              server_key=keyed.keys.server_key)
        async with monitor as c:
            reads = await asyncio.gather(*(c.read(FEED_R) for _ in range(20)))
            assert len(set(reads)) == 1
            with pytest.raises(AdsError, match="role monitor may not write") as refused:
                await c.write(FEED_W, 500)
            assert refused.value.code == INVALIDACCESS
            assert await c.read(FEED_R) == reads[0]
        async with AsyncClient(keyed.endpoint, key_file=keyed.keys.client("operator")) as c:
            await c.write(FEED_W, 999)
            assert await c.read(FEED_R) == 999
            await c.write(FEED_W, 1000)

    asyncio.run(main())


def test_the_service_logs_each_admitted_client_with_its_role(keyed: ServiceProcess) -> None:
    with client(keyed, "operator") as c:
        c.info()
    keyed.wait_for_log(r"ZeroMQ client operator \(role operator\) at 127\.0\.0\.1 admitted")
    keyed.wait_for_log(r"CURVE on: server public key \S{40}; allow-list .*"
                       r"\(monitor 1, operator 1, admin 1\)")
