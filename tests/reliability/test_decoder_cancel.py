"""RESET ends any program's decoding within a bound; no thread of an old run outlives it
(issue 35, hole 2).

The decoder once looked for a RESET only at loop passes. An MDI of local subprograms 19
deep, each calling the next 4 times (4^19 calls, no loop), never passed one: RESET
answered and the channel took new work, but the old ``cnc-sda-ch1`` thread went on
computing, under the realtime clock at the cycle's SCHED_FIFO priority (it inherited it
from the cycle thread), and rounds of MDI + RESET left spinning threads that starved the
service's own threads, up to a SIGTERM that never ended the service. 90 000 labels and a
backward ``$GOTO`` cost 1.4 s a pass, and the look came every 1024 passes. A ``$WHILE``
with only a ``#MSG`` inside ran for a million passes before the loop guard.

Now the decoder counts its work (``nc.work_guard``) and looks at its run every few
hundred steps; the kernel starts, counts and joins its workers (``kernel.workers``),
below the cycle's priority and below the service's threads.
"""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Iterator

import pytest

from cnc_objects.clients import AsyncClient
from cnc_objects.protocol.values import ChannelState
from cnc_objects.service.kernel.channel_mode import ChannelState as KernelChannelState
from cnc_objects.service.kernel.commands import (
    ManualBlock,
    ResetChannel,
    SelectProgram,
    StartProgram,
)
from cnc_objects.testing import serving, start_service
from cnc_objects.testing.helpers import wait_for_async
from tests.support.endless_programs import many_labels, nested_calls
from tests.support.kernel import KernelHarness

THREAD_END_S = 2.0  # a cancelled run's decoder thread has ended within this (bound)
SIGTERM_EXIT_S = 2.0  # SIGTERM ends the service within this
ROUNDS = 10
ENDLESS_PROGRAM = 20226  # the decoder's endless-program guard (ISG-style id)


def _decoders() -> set[threading.Thread]:
    return {t for t in threading.enumerate() if t.name.startswith("cnc-sda-")}


@pytest.fixture
def kernel() -> Iterator[KernelHarness]:
    with KernelHarness() as harness:
        yield harness


def _start_then_reset(kernel: KernelHarness, start: object) -> None:
    """Apply ``start``, RESET while its decoder computes; its thread ends within
    ``THREAD_END_S`` and the kernel counts no worker."""
    before = _decoders()
    kernel.begin(start)  # applied: the run's decoder thread is started
    started = _decoders() - before
    assert started, "the run started no decoder thread"
    assert kernel.kernel.snapshot.channels[0].state == KernelChannelState.ACTIVE
    assert kernel.command(ResetChannel(0, True)) is None
    for thread in started:
        thread.join(THREAD_END_S)
    alive = [t.name for t in started if t.is_alive()]
    assert not alive, f"{alive} still decoding {THREAD_END_S} s after RESET"
    assert kernel.kernel.workers.alive() == 0


def test_reset_ends_the_nested_subprogram_mdi_and_the_channel_works_again(
        kernel: KernelHarness) -> None:
    text = nested_calls()
    assert len(text) < 700  # the 685 bytes
    _start_then_reset(kernel, ManualBlock(0, text))
    start_x = kernel.kernel.snapshot.channels[0].axes[0].position_mm
    run = kernel.mdi("G91 G1 X1 F6000\n", timeout_s=30.0)
    assert run.channel.state == KernelChannelState.READY
    assert run.positions_mm[0] == pytest.approx(start_x + 1.0)


def test_ten_rounds_of_mdi_and_reset_leave_no_thread(kernel: KernelHarness) -> None:
    threads_before = set(threading.enumerate())
    for _ in range(ROUNDS):
        _start_then_reset(kernel, ManualBlock(0, nested_calls()))
    assert set(threading.enumerate()) == threads_before
    assert kernel.kernel.workers.alive() == 0


def test_reset_ends_a_backward_goto_over_90000_labels(kernel: KernelHarness) -> None:
    kernel.programs["labels.nc"] = many_labels()
    assert kernel.command(SelectProgram(0, "labels.nc")) is None
    _start_then_reset(kernel, StartProgram(0, True))


async def test_while_with_only_a_message_hits_the_endless_program_guard(tmp_path) -> None:
    """The guard counts work, not loop passes: a ``$WHILE`` whose body is a ``#MSG``
    ends with 20226 at a line of the loop, with file, line and column, after the
    configured number of steps ([limits] decoder_idle_steps_max)."""
    config = tmp_path / "guard.toml"
    config.write_text("[limits]\ndecoder_idle_steps_max = 20000\n")
    program = '%msg\nG0 X1\n$WHILE 1\n  #MSG ["still here"]\n$ENDWHILE\nM30\n'
    with serving("--config", str(config)) as service:
        async with AsyncClient(service.endpoint, timeout_s=30.0) as c:
            await c.upload("msg.nc", program.encode())
            await c.run_program("msg.nc")
            await wait_for_async(c, "ch1.mc_active_state_r",
                                 lambda state: state == ChannelState.ERROR, timeout_s=20.0)
            values = await c.read_many([
                "ch1.mc_error_1_id_r", "ch1.mc_error_1_file_r", "ch1.mc_error_1_line_r",
                "ch1.mc_error_1_column_r", "ch1.mc_error_1_text_r"])
    assert values["ch1.mc_error_1_id_r"] == ENDLESS_PROGRAM
    assert values["ch1.mc_error_1_file_r"] == "msg.nc"
    line = values["ch1.mc_error_1_line_r"]
    assert line in (3, 4, 5)  # the loop's lines: where the decoder stood
    assert values["ch1.mc_error_1_column_r"] == (3 if line == 4 else 1)
    assert "20000 steps" in values["ch1.mc_error_1_text_r"]


def _fifo_priorities(pid: int) -> list[int]:
    """The SCHED_FIFO priority of every thread of process ``pid`` (0: SCHED_OTHER)."""
    priorities = []
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            fifo = os.sched_getscheduler(int(tid)) == os.SCHED_FIFO
            priorities.append(os.sched_getparam(int(tid)).sched_priority if fifo else 0)
        except (ProcessLookupError, FileNotFoundError):  # a thread that just ended
            continue
    return priorities


def _threads_settle(pid: int, count: int) -> list[int]:
    """``_fifo_priorities(pid)`` once the process has ``count`` threads, or after
    ``THREAD_END_S`` (the last reading)."""
    deadline = time.monotonic() + THREAD_END_S
    while True:
        priorities = _fifo_priorities(pid)
        if len(priorities) == count or time.monotonic() > deadline:
            return priorities
        time.sleep(0.01)  # a poll of /proc: the threads' end has no event to wait on


def _fifo_permitted() -> bool:
    try:
        param = os.sched_getparam(0)
        policy = os.sched_getscheduler(0)
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(1))
        os.sched_setscheduler(0, policy, param)
    except (OSError, AttributeError):
        return False
    return True


@pytest.mark.skipif(not _fifo_permitted(), reason="SCHED_FIFO is refused on this machine "
                    "(needs root or CAP_SYS_NICE): the starvation needs real-time threads")
async def test_sigterm_ends_the_realtime_service_while_such_programs_decode() -> None:
    """Realtime clock at SCHED_FIFO 60 (the default): rounds of the nested MDI and RESET,
    then one more left decoding, then SIGTERM: the service ends within
    ``SIGTERM_EXIT_S``. (The decoders once ran at the cycle's priority, and a few of
    them starved the service's threads: SIGTERM never ended it.)"""
    # with CURVE keys: the service's ZAP thread (ZeroMQ's authentication) is one of the
    # threads the shutdown waits for
    service = start_service("--clock", "realtime", "--rt-priority", "60", keys=True)
    try:
        grant = service.wait_for_log(r"cycle thread under", timeout_s=10.0)
        if "SCHED_FIFO priority 60" not in grant:
            pytest.skip(f"the service got no real-time priority: {grant}")
        assert service.keys is not None
        threads_idle = len(_fifo_priorities(service.process.pid))
        async with AsyncClient(service.endpoint, timeout_s=30.0,
                               key_file=service.keys.client("operator")) as c:
            for _ in range(ROUNDS):
                await c.mdi(nested_calls())
                await c.reset()
            await c.mdi(nested_calls())
            assert await c.read("ch1.mc_active_state_r") == ChannelState.ACTIVE
            # one decoder more than at rest (the run's), and only the cycle thread at
            # the cycle's priority: the others below it, the decoder below the service's
            # (the RESET is answered before the old run's decoder has ended: it ends
            # within its next few hundred steps, THREAD_END_S is the bound)
            priorities = _threads_settle(service.process.pid, threads_idle + 1)
            assert len(priorities) == threads_idle + 1, sorted(priorities)
            assert sorted(priorities)[-2:] == [59, 60], priorities
            assert sorted(priorities)[0] < 59, priorities
        sent_s = time.monotonic()
        service.process.send_signal(signal.SIGTERM)
        try:
            code = service.process.wait(timeout=SIGTERM_EXIT_S)
        except Exception:
            code = None
        took_s = time.monotonic() - sent_s
        assert code == 0, f"SIGTERM: exit {code} after {took_s:.1f} s"
    finally:
        service.stop()


def test_reset_ends_an_endless_look_ahead_section(kernel: KernelHarness) -> None:
    """Under LA_ON the decoder collects a section's blocks before it hands any over (up
    to 500 000): it looks for the RESET at each block it collects."""
    kernel.programs["la.nc"] = "G1 F1000\nLA_ON\n$WHILE 1\nG1 X1\nG1 X0\n$ENDWHILE\nM30\n"
    assert kernel.command(SelectProgram(0, "la.nc")) is None
    _start_then_reset(kernel, StartProgram(0, True))
