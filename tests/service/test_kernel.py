"""The kernel and its cycle thread, without any socket: commands, snapshots, run control."""

from __future__ import annotations

import time
from collections.abc import Iterator
from dataclasses import dataclass

import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.clock import RealtimeClock, VirtualClock
from cnc_objects.service.kernel.commands import Refusal, RefusalReason, SetExecutionMode, SetFeedOverride
from cnc_objects.service.kernel.kernel import Control, ControlCommand, Kernel, ResetCycleStats
from cnc_objects.service.kernel.kernel_state import KernelState
from cnc_objects.service.kernel.state import LinkState
from tests.support.kernel_commands import Applied, submit


@pytest.fixture
def kernel() -> Iterator[Kernel]:
    k = Kernel(build_config(), VirtualClock(0.001))
    k.start()
    yield k
    k.close()


def test_initial_links_follow_the_configuration() -> None:
    state = KernelState.from_config(build_config())
    main, jog = state.channels
    assert [(a.requested_link, a.actual_link, a.link_state) for a in main.axes] == [
        (1, 1, LinkState.LINKED), (2, 2, LinkState.LINKED), (3, 3, LinkState.LINKED)
    ]
    assert jog.suspend.output_suspended
    assert [(a.requested_link, a.actual_link, a.link_state) for a in jog.axes] == [
        (1, 0, LinkState.REQUESTED), (2, 0, LinkState.REQUESTED), (3, 0, LinkState.REQUESTED)
    ]
    assert [p.linked_logical_axis for p in state.physical_axes] == [1, 2, 3]


def test_command_is_visible_in_the_snapshot_once_applied(kernel: Kernel) -> None:
    assert submit(kernel, SetFeedOverride(0, 420)) is None
    snapshot = kernel.snapshot
    assert snapshot.channels[0].switches.feed_override_per_mille == 420
    assert snapshot.channels[1].switches.feed_override_per_mille == 1000


def test_snapshot_is_a_copy_the_kernel_does_not_change(kernel: Kernel) -> None:
    before = kernel.snapshot
    assert submit(kernel, SetFeedOverride(0, 10)) is None
    assert before.channels[0].switches.feed_override_per_mille == 1000
    assert kernel.snapshot.cycle > before.cycle


def test_refusals_say_why(kernel: Kernel) -> None:
    refusal = submit(kernel, SetFeedOverride(0, 1001))
    assert refusal is not None and refusal.reason is RefusalReason.INVALID_VALUE
    assert "100.1 %" in refusal.message
    refusal = submit(kernel, SetExecutionMode(0, 0x102))
    assert refusal is not None and "SOLLKON|KIN_TRAFO_OFF" in refusal.message
    refusal = submit(kernel, SetExecutionMode(0, -1))
    assert refusal is not None and refusal.reason is RefusalReason.INVALID_VALUE


def test_commands_apply_in_arrival_order(kernel: Kernel) -> None:
    results = [Applied() for _ in range(50)]
    for value, done in enumerate(results):
        kernel.submit(SetFeedOverride(0, value), done)
    assert all(d.wait() is None for d in results)
    assert kernel.snapshot.channels[0].switches.feed_override_command == 49


def test_stop_refuses_commands_and_run_resumes(kernel: Kernel) -> None:
    assert submit(kernel, ControlCommand(Control.STOP)) is None
    assert kernel.running is False and kernel.snapshot.stats.running is False
    cycles = kernel.snapshot.cycle
    refusal = submit(kernel, SetFeedOverride(0, 5))
    assert refusal is not None and refusal.reason is RefusalReason.NOT_READY
    assert kernel.snapshot.cycle == cycles  # no cycle ran while stopped
    assert submit(kernel, ControlCommand(Control.RUN)) is None
    assert submit(kernel, SetFeedOverride(0, 5)) is None


def test_reset_reinitialises_state(kernel: Kernel) -> None:
    assert submit(kernel, SetFeedOverride(0, 5)) is None
    assert submit(kernel, ControlCommand(Control.RESET)) is None
    assert kernel.snapshot.channels[0].switches.feed_override_command == 1000


@dataclass(frozen=True)
class Explodes:
    """A command whose apply raises: the kernel must survive it."""

    def apply(self, state: KernelState) -> Refusal | None:
        raise RuntimeError("boom")


def test_a_failing_command_is_refused_and_the_kernel_goes_on(kernel: Kernel) -> None:
    refusal = submit(kernel, Explodes())
    assert refusal is not None and refusal.reason is RefusalReason.NOT_READY
    assert submit(kernel, SetFeedOverride(0, 7)) is None


def test_submit_after_close_is_refused_at_once() -> None:
    k = Kernel(build_config(), VirtualClock(0.001))
    k.start()
    k.close()
    refusal = submit(k, SetFeedOverride(0, 1))
    assert refusal is not None and refusal.reason is RefusalReason.NOT_READY


def test_virtual_clock_is_deterministic_in_kernel_time(kernel: Kernel) -> None:
    assert submit(kernel, SetFeedOverride(0, 1)) is None
    snap = kernel.snapshot
    assert snap.time_ns == snap.cycle * 1_000_000


@dataclass(frozen=True)
class TakesTime:
    """A command that keeps the cycle busy longer than a cycle lasts."""

    seconds: float

    def apply(self, state: KernelState) -> Refusal | None:
        end = time.perf_counter() + self.seconds
        while time.perf_counter() < end:
            pass
        return None


def test_realtime_clock_counts_overruns_and_jitter() -> None:
    k = Kernel(build_config(), RealtimeClock(0.001))
    k.start()
    try:
        assert submit(k, TakesTime(0.005)) is None
        assert submit(k, SetFeedOverride(0, 1)) is None  # a later cycle has published stats
        stats = k.snapshot.stats
        assert stats.overruns >= 1
        assert stats.exec_time_max_us >= 5000
        assert stats.cycles > 0
    finally:
        k.close()


def test_cycle_lateness_is_kept_per_cycle_and_reset_on_command() -> None:
    """The realtime clock puts every cycle's lateness into a histogram: the p50/p99
    objects read it; cnc_cycle_stats_reset_w (ResetCycleStats) starts the figures again."""
    k = Kernel(build_config(), RealtimeClock(0.001))
    k.start()
    try:
        lateness = k.lateness
        assert lateness is not None
        deadline = time.monotonic() + 5
        while lateness.total < 20:
            assert time.monotonic() < deadline, "no cycles counted"
            time.sleep(0.01)
        for _ in range(100 * lateness.total):  # as if nearly every cycle had been 50 ms late
            lateness.add(50_000)
        k.stats.overruns, k.stats.jitter_max_us = 1000, 50_000
        assert lateness.percentile_us(0.5) == 50_010
        assert submit(k, ResetCycleStats(False)) is None  # FALSE: nothing happens
        assert lateness.percentile_us(0.5) == 50_010
        assert submit(k, ResetCycleStats(True)) is None
        assert lateness.total < 20 and lateness.percentile_us(0.99) < 50_000
        assert k.stats.overruns < 1000 and k.stats.jitter_max_us < 50_000
    finally:
        k.close()


def test_the_virtual_clock_keeps_no_lateness(kernel: Kernel) -> None:
    assert kernel.lateness is None
    assert submit(kernel, ResetCycleStats(True)) is None
