"""Why a channel stands (``ch<c>.mc_wait_reason_r``), each reason provoked over the wire.

A real cnc-service on the virtual clock (one on the realtime clock for the decoder):
every test sets the channel up through objects, starts a real NC program (or a manual
block, or a command) and waits, by subscription, until the wait reason object names the
reason; the text object says the same. The channel is RESET after each test and what a
test switched on is switched off again.
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from cnc_objects.clients import AsyncClient, Client
from cnc_objects.protocol.values import ExecutionMode
from cnc_objects.protocol.wait_reasons import WAIT_REASON_TEXTS, WaitReason
from cnc_objects.testing import ServiceProcess, serving, wait_for
from tests.support.pyads_plc import plc_machine
from tests.support.service import reset_client, serving_config

REASON, TEXT = "ch1.mc_wait_reason_r", "ch1.mc_wait_reason_text_r"
CONFIG = plc_machine({"11": "MVS_SVS"})
SUSPEND = "gpCh[0].bahn_mc_control.suspend_axis_output.command_w"
LONG_DWELL = "G4 X100000\nM30\n"  # a dwell the tests never wait out


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    with serving_config(tmp_path_factory.mktemp("wait-reasons"), CONFIG) as service:
        yield service


@pytest.fixture
def c(machine: ServiceProcess) -> Iterator[Client]:
    with reset_client(machine) as client:
        yield client
        client.reset(1)


def run(c: Client, text: str) -> None:
    c.upload("wait.nc", text.encode())
    c.run_program("wait.nc", 1)


def expect(c: Client, reason: WaitReason) -> None:
    """The reason object names ``reason`` (seen by subscription), the text object says
    it as a sentence."""
    wait_for(c, REASON, int(reason), timeout_s=30)
    if reason != WaitReason.NONE:
        text = c.read(TEXT)
        assert text == WAIT_REASON_TEXTS[reason] and text


def switched(c: Client, name: str, on: object, off: object) -> Callable[[], None]:
    """Write ``on`` now; the returned function writes ``off``."""
    c.write(name, on)
    return lambda: c.write(name, off)


def test_an_idle_channel_waits_for_nothing(c: Client) -> None:
    assert c.read(REASON) == WaitReason.NONE and c.read(TEXT) == ""
    assert c.describe(REASON).enum[int(WaitReason.FEED_HOLD)] == "FEED_HOLD"


def test_single_block_waits_for_start_after_a_block(c: Client) -> None:
    undo = switched(c, "ch1.mc_command_single_block_w", True, False)
    try:
        run(c, "G1 X1 F6000\nG1 X2\nM30\n")
        expect(c, WaitReason.SINGLE_BLOCK)
        c.start(1)  # the next block runs, and the path stops after it again
        wait_for(c, "ch1.mc_block_count_r", 2, timeout_s=30)
        expect(c, WaitReason.SINGLE_BLOCK)
    finally:
        undo()


@pytest.mark.parametrize(("stop", "reason"), [
    ("M0", WaitReason.PROGRAMMED_STOP), ("M1", WaitReason.OPTIONAL_STOP)])
def test_m0_and_m1_wait_for_start(c: Client, stop: str, reason: WaitReason) -> None:
    undo = switched(c, "ch1.mc_command_M01_stop_enable_w", True, False)  # M1 needs it
    try:
        run(c, f"G1 X1 F6000\n{stop}\nG1 X2\nM30\n")
        expect(c, reason)
        c.start(1)
        c.wait_program(1, 30)
        assert c.read(REASON) == WaitReason.NONE
    finally:
        undo()


def test_feed_hold_waits_for_start(c: Client) -> None:
    run(c, LONG_DWELL)
    expect(c, WaitReason.DWELL)
    c.hold(1)
    expect(c, WaitReason.FEED_HOLD)
    c.start(1)
    expect(c, WaitReason.DWELL)


def test_override_zero_stands_with_motion_to_do(c: Client) -> None:
    undo = switched(c, "ch1.mc_command_feed_override_w", 0, 1000)
    try:
        run(c, "G1 X1 F6000\nM30\n")
        expect(c, WaitReason.OVERRIDE_ZERO)
    finally:
        undo()
    c.wait_program(1, 30)


def test_an_m_function_waits_for_the_plc_acknowledge(c: Client) -> None:
    run(c, "G1 X1 F6000 M11\nM30\n")  # M11: MVS_SVS, acknowledged by the PLC only
    expect(c, WaitReason.PLC_ACKNOWLEDGE)
    c.write("gpCh[0].techno_unit_std_sync[0].command_w", True)
    c.wait_program(1, 30)
    assert c.read(REASON) == WaitReason.NONE


def test_m3_waits_for_the_spindle_speed(c: Client) -> None:
    run(c, "S3000 M3\nG1 X1 F6000\nM5\nM30\n")
    expect(c, WaitReason.SPINDLE)
    c.wait_program(1, 30)


def test_dwell(c: Client) -> None:
    run(c, LONG_DWELL)
    expect(c, WaitReason.DWELL)


def test_extended_mdi_waits_for_the_next_manual_block(c: Client) -> None:
    undo = switched(c, "ch1.mc_command_execution_mode_w", int(ExecutionMode.ADD_MDI_BLOCK), 0)
    try:
        c.mdi("G91 G1 X1 F6000", 1)
        expect(c, WaitReason.MANUAL_BLOCK)
    finally:
        undo()


def test_suspended_axis_output_holds_the_path(c: Client) -> None:
    undo = switched(c, SUSPEND, True, False)
    try:
        run(c, "G1 X1 F6000\nM30\n")
        expect(c, WaitReason.OUTPUT_SUSPENDED)
    finally:
        undo()
    c.wait_program(1, 30)


def test_a_start_waits_for_its_axes_to_link(tmp_path: Path) -> None:
    """Suspended output, then released: the program's start waits while the axes link
    again (a few cycles). The step clock shows every one of those cycles."""
    with serving("--clock", "step", program_dir=tmp_path / "programs") as service, \
            Client(service.endpoint, timeout_s=10) as c:
        c.write(SUSPEND, True)  # writes between steps are applied at once
        c.upload("wait.nc", b"G1 X1 F6000\nM30\n")
        c.run_program("wait.nc", 1)
        c.write("cnc_cycle_step_w", 5)
        assert c.read(REASON) == WaitReason.OUTPUT_SUSPENDED
        c.write(SUSPEND, False)
        seen: list[int] = []
        for _ in range(1000):  # a few cycles of linking, then the path moves
            c.write("cnc_cycle_step_w", 1)
            reason = c.read(REASON)
            if not seen or seen[-1] != reason:
                seen.append(reason)
            if reason == WaitReason.NONE:
                break
    assert seen == [WaitReason.AXIS_LINK, WaitReason.NONE]


def test_a_paused_syntax_check_waits_for_start(c: Client) -> None:
    check = int(ExecutionMode.SYNCHK | ExecutionMode.MACHINE_LOCK)
    undo_mode = switched(c, "ch1.mc_command_execution_mode_w", check, 0)
    undo_single = switched(c, "ch1.mc_command_single_block_w", True, False)
    try:
        run(c, "G1 X1 F6000\nG1 X2\nM30\n")
        expect(c, WaitReason.CHECK_PAUSE)
    finally:
        undo_single()
        undo_mode()


def test_an_error_waits_for_reset(c: Client) -> None:
    run(c, "G1 X1 F6000\nG1 X=\nM30\n")
    expect(c, WaitReason.ERROR)
    c.reset(1)
    expect(c, WaitReason.NONE)


async def test_the_path_waits_for_the_decoder(tmp_path: Path) -> None:
    """Realtime clock: a long loop without motion between two blocks leaves the path
    without blocks while the decoder computes (the virtual clock would wait for it).

    The subscription is live (its first sample arrived) before the program starts: on a
    loaded machine the SCHED_FIFO service may decode the whole loop before a watcher
    that subscribes afterwards is heard."""
    loop = "$FOR V.L.K = 1, 200000\n$ENDFOR\n"  # seconds of decoding
    program = f"#VAR\nV.L.K = 0\n#ENDVAR\nG1 X1 F6000\n{loop}G1 X2\nM30\n"
    with serving("--clock", "realtime", program_dir=tmp_path) as service:
        async with AsyncClient(service.endpoint, timeout_s=10) as c:
            seen: list[int] = []
            async with contextlib.aclosing(c.subscribe(REASON, cycle_ms=0)) as samples:
                seen.append((await anext(samples)).value)
                await c.upload("wait.nc", program.encode())
                await c.run_program("wait.nc", 1)
                async with asyncio.timeout(30):
                    async for sample in samples:
                        seen.append(sample.value)
                        if sample.value == WaitReason.DECODER:
                            break
            assert seen[0] == WaitReason.NONE and seen[-1] == WaitReason.DECODER, seen
            await c.reset(1)
