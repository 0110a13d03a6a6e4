"""Software limits are monitored once an axis is referenced (P-AXIS-00705
``kenngr.swe_check``, ISG's default -1); 1 monitors them from start-up, 0 never.

ISG's pages disagree: the programming manual's POS_LIMIT page says the limits are
monitored "after controller start-up", the parameter's own page (and the homing page: a
position before homing means nothing) says "after completion of homing". The parameter's
page is followed (docs/manual.md "Software limits and homing")."""

from __future__ import annotations

import copy
from collections.abc import Iterator

import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.machine_config import DEFAULT_MACHINE, MachineConfig
from cnc_objects.service.param_list import ParamListError, parse_axis_list
from tests.support.kernel import KernelHarness

SW_LIMIT = 50101  # the path would cross a software limit
BEYOND = "G53 G01 X1200 F60000\nM30\n"  # the default X limit is +1000 mm


def _machine(check: int | None) -> MachineConfig:
    """The default machine; with ``check`` as every axis's ``sw_limit_check``."""
    data = copy.deepcopy(DEFAULT_MACHINE)
    if check is not None:
        for channel in data["channels"]:
            for axis in channel["axes"]:
                axis.setdefault("limits", {})["sw_limit_check"] = check
    return build_config(data)


@pytest.fixture
def fresh() -> Iterator[KernelHarness]:
    with KernelHarness(config=_machine(None)) as harness:
        yield harness


def test_an_unreferenced_axis_passes_its_limit(fresh: KernelHarness) -> None:
    run = fresh.run(BEYOND)
    assert run.channel.state == ChannelState.READY, run.channel.errors.entries
    assert run.positions_mm[0] == pytest.approx(1200.0)


def test_a_referenced_axis_stops_before_its_limit(fresh: KernelHarness) -> None:
    fresh.home()
    run = fresh.run(BEYOND)
    assert run.channel.state == ChannelState.ERROR
    assert [(e.id, e.line) for e in run.channel.errors.entries] == [(SW_LIMIT, 1)]
    assert run.positions_mm[0] == 0.0  # refused before the axis moved


def test_check_1_monitors_from_start_up_and_0_never() -> None:
    with KernelHarness(config=_machine(1)) as always:
        run = always.run(BEYOND)
        assert [e.id for e in run.channel.errors.entries] == [SW_LIMIT]
    with KernelHarness(config=_machine(0)) as never:
        never.home()
        run = never.run(BEYOND)
        assert run.channel.state == ChannelState.READY, run.channel.errors.entries


def test_a_syntax_check_follows_the_same_rule(fresh: KernelHarness) -> None:
    from cnc_objects.protocol.values import ExecutionMode
    from cnc_objects.service.kernel.commands import SetExecutionMode

    check = int(ExecutionMode.SYNCHK | ExecutionMode.MACHINE_LOCK)
    assert fresh.command(SetExecutionMode(0, check)) is None
    assert fresh.run(BEYOND).channel.state == ChannelState.READY
    fresh.home()
    assert [e.id for e in fresh.run(BEYOND).channel.errors.entries if not e.warning] == [
        SW_LIMIT]


def test_the_axis_list_sets_the_check() -> None:
    base = "kopf.achs_nr 1\n"
    assert parse_axis_list(base + "kenngr.swe_check 1\n", "x.lis")["limits"] == {
        "sw_limit_check": 1}
    assert parse_axis_list(base + "kenngr.swe_check -1\n", "x.lis")["limits"] == {
        "sw_limit_check": -1}
    with pytest.raises(ParamListError, match="swe_check.*out of range -1..1"):
        parse_axis_list(base + "kenngr.swe_check 2\n", "x.lis")


def test_a_manual_jog_of_an_unreferenced_axis_passes_its_limit_until_homed() -> None:
    from cnc_objects.protocol.values import ChannelMode, ManualOperationMode
    from cnc_objects.service.kernel.commands import SelectMode
    from cnc_objects.service.kernel.commands_manual import ManualAxisCommand
    from tests.support.manual_machine import LIMIT_MAX_MM, REF_MM, machine

    with KernelHarness(config=machine(sw_limit_check=-1)) as k:
        def jog_10_mm() -> float:
            before = k.kernel.snapshot.cycle
            assert k.command(ManualAxisCommand(0, 0, "jog_plus", True)) is None
            snap = k.wait_for(lambda s: s.cycle > before + 2 and not s.channels[0].manual[0].moving)
            assert k.command(ManualAxisCommand(0, 0, "jog_plus", False)) is None
            return snap.channels[0].axes[0].position_mm

        assert k.command(SelectMode(0, ChannelMode.MANUAL)) is None
        for action, value in (("operation_mode", ManualOperationMode.INCREMENTAL),
                              ("increment", 100_000)):  # 10 mm
            assert k.command(ManualAxisCommand(0, 0, action, value)) is None
        assert jog_10_mm() == pytest.approx(10.0)  # beyond the 8 mm limit: not monitored
        assert k.command(ManualAxisCommand(0, 0, "homing_start", True)) is None
        homed = k.wait_for(lambda s: s.channels[0].manual[0].referenced)
        assert homed.channels[0].axes[0].position_mm == pytest.approx(REF_MM)
        assert jog_10_mm() == pytest.approx(LIMIT_MAX_MM)  # now it stops at the limit
