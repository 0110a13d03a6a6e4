"""Alarms over the wire (real service, virtual clock): the lists as objects, read with the
client (ZeroMQ) and with pyads (ADS/TCP); acknowledge and its refusal; RESET clearing;
the events of ``alarm_events``; ``cnc alarms`` (docs/alarms.md)."""

from __future__ import annotations

import asyncio
import subprocess
import sys
from collections.abc import Iterator

import pyads
import pytest

from cnc_objects.clients import (
    AdsError,
    AdsReturnCode,
    AlarmEvent,
    AsyncClient,
    ChannelError,
    Client,
)
from cnc_objects.protocol.alarm_values import AlarmClass, AlarmState, Severity
from cnc_objects.testing import ServiceProcess, serving
from tests.e2e.test_ads_pyads import Ads, ads  # noqa: F401  (the pyads fixture)
from tests.support.cli import cnc, json_lines
from tests.support.service import reset_client, serving_config

BAD = "G0 X1\nG1 X10\nM30\n"  # line 2: G1 without F, NC error 20008


@pytest.fixture(scope="module")
def machine(tmp_path_factory) -> Iterator[ServiceProcess]:
    """One service for this module, with a history of 3 alarms."""
    with serving_config(tmp_path_factory.mktemp("alarms"),
                        "[limits]\nalarm_history_max = 3\n") as service:
        yield service


@pytest.fixture
def c(machine) -> Iterator[Client]:
    with reset_client(machine) as client:
        yield client


def fail_with(c: Client, text: str = BAD, name: str = "bad.nc") -> None:
    """Run ``text``, which ends in ERROR."""
    c.upload(name, text.encode())
    c.run_program(name, 1)
    with pytest.raises(ChannelError):
        c.wait_program(1, 30)


def test_an_nc_error_is_an_active_alarm_with_its_place(c) -> None:
    fail_with(c)
    listed = c.alarms()
    assert listed.active_count == 1
    [alarm] = listed.active
    assert (alarm.id, alarm.severity, alarm.alarm_class, alarm.state, alarm.channel) == (
        20008, Severity.ERROR, AlarmClass.DECODER, AlarmState.ACTIVE, 1)
    assert alarm.where == "bad.nc:2:1"
    assert alarm.cycle > 0 and alarm.kernel_ns > 0 and alarm.wall_ns > 0
    assert str(alarm).startswith(f"#{alarm.sequence} active error 20008 ch1: bad.nc:2:1: ")


def test_acknowledge_then_reset_clears_and_the_history_keeps_it(c) -> None:
    fail_with(c)
    alarm = c.alarms().active[0]
    c.acknowledge_alarm(alarm.sequence)
    assert [a.state for a in c.alarms().active] == [AlarmState.ACKNOWLEDGED]
    c.reset(1)
    listed = c.alarms(history=True)
    assert listed.active == () and listed.active_count == 0
    assert (listed.history[0].sequence, listed.history[0].state) == (alarm.sequence,
                                                                     AlarmState.CLEARED)


def test_an_unknown_sequence_number_is_refused_with_0x70c_and_a_sentence(c) -> None:
    with pytest.raises(AdsError) as refused:
        c.acknowledge_alarm(4_000_000)
    assert refused.value.code == AdsReturnCode.DEVICE_NOTFOUND
    assert "no alarm has the sequence number 4000000" in str(refused.value)


def test_the_history_is_bounded_by_its_limit(c) -> None:
    for _ in range(4):
        c.reset(1)
        fail_with(c)
    listed = c.alarms(history=True)
    assert len(listed.history) == 3  # [limits] alarm_history_max = 3
    assert c.read("alarm_history_count_r") == 3
    sequences = [a.sequence for a in listed.history]
    assert sequences == sorted(sequences, reverse=True)  # newest first
    assert not c.browse("alarm_history[4].*")  # as many slot objects as the limit


async def test_events_come_as_they_happen(machine) -> None:
    async with AsyncClient(machine.endpoint, timeout_s=10) as watcher, \
            AsyncClient(machine.endpoint, timeout_s=10) as actor:
        await actor.reset(1)
        events = watcher.alarm_events()
        first = asyncio.ensure_future(anext(events))
        # the events start at the subscription's first sample: wait until it is in place
        await asyncio.wait_for(_subscribed(machine), 30)
        await actor.upload("bad.nc", BAD.encode())
        await actor.run_program("bad.nc", 1)
        raised: AlarmEvent = await asyncio.wait_for(first, 30)
        assert (raised.kind, raised.alarm.id) == ("raised", 20008)
        await actor.acknowledge_alarm(raised.alarm.sequence)
        acked = await asyncio.wait_for(anext(events), 30)
        assert (acked.kind, acked.alarm.sequence) == ("acknowledged", raised.alarm.sequence)
        await actor.reset(1)
        cleared = await asyncio.wait_for(anext(events), 30)
        assert (cleared.kind, cleared.alarm.sequence) == ("cleared", raised.alarm.sequence)
        await events.aclose()


async def _subscribed(machine: ServiceProcess) -> None:
    async with AsyncClient(machine.endpoint, timeout_s=10) as c:
        while await c.read("cnc_notifications_r") < 1:
            await c.read("alarm_changes_r")  # a round trip, not a sleep


def test_cnc_alarms_lists_and_acknowledges(c, machine) -> None:
    fail_with(c)
    ep = machine.endpoint
    shown = cnc("alarms", endpoint=ep)
    assert shown.returncode == 0, shown.stderr
    lines = shown.stdout.splitlines()
    assert lines[0] == "1 active alarm"
    assert "active error 20008 ch1: bad.nc:2:1: " in lines[1]
    [record] = json_lines(cnc("--json", "alarms", endpoint=ep))
    assert (record["id"], record["state"], record["class"], record["line"]) == (
        20008, "active", "decoder", 2)
    acked = cnc("alarms", "ack", str(record["sequence"]), endpoint=ep)
    assert acked.returncode == 0 and f"acknowledged alarm #{record['sequence']}" in acked.stdout
    [record] = json_lines(cnc("--json", "alarms", endpoint=ep))
    assert record["state"] == "acknowledged"
    unknown = cnc("alarms", "ack", "4000000", endpoint=ep)
    assert unknown.returncode == 1 and "0x70c notfound: no alarm has" in unknown.stderr.lower()
    both = cnc("alarms", "ack", endpoint=ep)
    assert both.returncode == 2 and "sequence number or --all" in both.stderr
    assert cnc("alarms", "ack", "--all", endpoint=ep).returncode == 0


def test_pyads_reads_the_alarm_list_by_name(ads: Ads) -> None:  # noqa: F811
    with Client(ads.service.endpoint, timeout_s=10) as c:
        c.reset(1)
        fail_with(c)
        sequence = c.alarms().active[0].sequence
    count = ads.com.read_by_name("alarm_active_count_r", pyads.PLCTYPE_UDINT)
    assert count >= 1
    assert ads.com.read_by_name("alarm_active[1].id", pyads.PLCTYPE_UDINT) == 20008
    assert ads.com.read_by_name("alarm_active[1].sequence", pyads.PLCTYPE_UDINT) == sequence
    assert ads.com.read_by_name("alarm_active[1].file", pyads.PLCTYPE_STRING) == "bad.nc"
    ads.com.write_by_name("alarm_acknowledge_w", sequence, pyads.PLCTYPE_UDINT)
    assert ads.com.read_by_name("alarm_active[1].state", pyads.PLCTYPE_UINT) == 2


def test_cnc_alarms_watch_prints_the_events(c, machine) -> None:
    c.acknowledge_all_alarms()
    argv = [sys.executable, "-c", "from cnc_objects.clients.cli import main; main()",
            "--endpoint", machine.endpoint, "alarms", "--watch", "--count", "2",
            "--wait-timeout", "60"]
    with subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          text=True) as watching:
        asyncio.run(asyncio.wait_for(_subscribed(machine), 30))
        fail_with(c)
        c.reset(1)
        out, err = watching.communicate(timeout=60)
    assert watching.returncode == 0, err
    # the list first (indented lines), then one unindented line per event
    events = [line.split(":")[0] for line in out.splitlines()
              if ": " in line and not line.startswith(" ")]
    assert events == ["raised", "cleared"], out
    assert "error 20008 ch1: bad.nc:2:1: " in out


def test_an_output_area_limit_is_a_service_alarm(tmp_path) -> None:
    config = tmp_path / "machine.toml"
    config.write_text("[limits]\noutput_max_file_bytes = 4096\n")
    with serving("--config", str(config)) as service, \
            Client(service.endpoint, timeout_s=10) as c:
        c.upload("loop.nc", b'$WHILE 1\n#MSG SAVE ["%d padding-padding", 1]\n$ENDWHILE\nM30\n')
        c.run_program("loop.nc", 1)
        with pytest.raises(ChannelError):
            c.wait_program(1, 60)
        [alarm] = c.alarms().active
        assert (alarm.id, alarm.alarm_class, alarm.severity) == (
            20533, AlarmClass.SERVICE, Severity.ERROR)
        assert alarm.where == "loop.nc:2:1" and "output_max_file_bytes" in alarm.text
