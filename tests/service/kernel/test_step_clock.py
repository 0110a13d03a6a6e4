"""The step clock in-process: cycles run only when granted, commands between cycles are
applied at once, and the edges of a step (a second step, STOP, shutdown) are answered."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.clock import VirtualClock
from cnc_objects.service.kernel.commands import (
    RefusalReason,
    SelectProgram,
    SetFeedOverride,
    StartProgram,
)
from cnc_objects.service.kernel.kernel import Control, ControlCommand, Kernel
from cnc_objects.service.kernel.step_clock import StepClock, StepCycles
from tests.support.event_speed import observed_values
from tests.support.kernel_commands import Applied, submit


@pytest.fixture
def kernel() -> Iterator[Kernel]:
    k = Kernel(build_config(), StepClock(0.001, max_cycles=1000))
    k.start()
    yield k
    k.close()


def test_no_cycle_runs_until_granted_and_a_step_runs_exactly_its_cycles(kernel: Kernel) -> None:
    assert submit(kernel, SetFeedOverride(0, 500)) is None  # applied without a cycle
    assert kernel.snapshot.cycle == 0
    assert kernel.snapshot.channels[0].switches.feed_override_command == 500
    assert submit(kernel, StepCycles(7)) is None
    assert (kernel.snapshot.cycle, kernel.stats.cycles) == (7, 7)
    assert kernel.snapshot.time_ns == 7 * kernel.cycle_ns


@pytest.mark.parametrize("cycles", [0, 1001])
def test_a_step_outside_the_limit_is_refused_and_runs_nothing(
    kernel: Kernel, cycles: int
) -> None:
    refusal = submit(kernel, StepCycles(cycles))
    assert refusal is not None and refusal.reason == RefusalReason.INVALID_VALUE
    assert f"grants 1 to 1000 cycles ([limits] step_max_cycles), not {cycles}" in refusal.message
    assert kernel.snapshot.cycle == 0


def test_a_step_written_during_a_step_is_refused_busy() -> None:
    k = Kernel(build_config(), StepClock(0.001))
    first, second = Applied(), Applied()
    k.submit(StepCycles(100), first)
    k.submit(StepCycles(1), second)  # queued: taken at the start of the first's first cycle
    k.start()
    try:
        assert first.wait() is None
        refusal = second.wait()
        assert refusal is not None and refusal.reason == RefusalReason.BUSY
        assert k.snapshot.cycle == 100
    finally:
        k.close()


def test_a_stop_during_a_step_ends_it_with_a_refusal() -> None:
    k = Kernel(build_config(), StepClock(0.001))
    step, stop = Applied(), Applied()
    k.submit(StepCycles(100), step)
    k.submit(ControlCommand(Control.STOP), stop)  # applied at the start of cycle 1
    k.start()
    try:
        assert stop.wait() is None
        refusal = step.wait()
        assert refusal is not None and refusal.reason == RefusalReason.NOT_READY
        assert "stopped after 1 of 100 cycles" in refusal.message
        assert submit(k, StepCycles(1)) is not None  # stopped: refused, as every write
        assert submit(k, ControlCommand(Control.RUN)) is None
        assert submit(k, StepCycles(2)) is None
        assert k.snapshot.cycle == 3
    finally:
        k.close()


def test_a_step_under_the_virtual_clock_is_refused_not_ready() -> None:
    k = Kernel(build_config(), VirtualClock(0.001))
    k.start()
    try:
        refusal = submit(k, StepCycles(1))
        assert refusal is not None and refusal.reason == RefusalReason.NOT_READY
        assert "only under --clock step" in refusal.message
    finally:
        k.close()


#: A zigzag of 5 mm blocks at F600 (0.5 s each, about 3 300 cycles in all).
_ZIGZAG = "G90 G1 F600\n" + "".join(f"X{(k % 2) * 5} Y{k * 0.5:g}\n" for k in range(6)) + "M30\n"
#: The grants of the bulk run, then the feed override written between two of them.
_GRANTS = (1, 1, 400, 1, 1234, 7, 600)
_OVERRIDE_AT = sum(_GRANTS[:3])  # cycles granted before the feed override is written


def _stepped_run(grants: tuple[int, ...], override_at: int | None = _OVERRIDE_AT
                 ) -> tuple[list[tuple[Any, ...]], int, int]:
    """Run the zigzag under the step clock, granting ``grants`` one after another (the
    feed override written before the grant that starts at cycle ``override_at``), then
    the rest one cycle at a time: what each grant's reply showed, the cycle the program
    ended at, and the cycles the kernel ran in bulk."""
    k = Kernel(build_config(), StepClock(0.001), {"p.nc": _ZIGZAG}.__getitem__,
               lambda name: name == "p.nc")
    k.start()
    seen = []
    try:
        assert submit(k, SelectProgram(0, "p.nc")) is None
        assert submit(k, StartProgram(0, True)) is None  # applied between cycles
        for cycles in grants:
            if k.snapshot.cycle == override_at:
                assert submit(k, SetFeedOverride(0, 700)) is None
            assert submit(k, StepCycles(cycles)) is None
            seen.append(observed_values(k.snapshot))
        while k.snapshot.channels[0].state != ChannelState.READY:
            assert k.snapshot.cycle < 10_000, "the program did not end"
            assert submit(k, StepCycles(1)) is None
        return seen, k.snapshot.cycle, k.stats.bulk_cycles
    finally:
        k.close()


def test_granted_cycles_nobody_watches_run_in_bulk_equal_to_single_steps() -> None:
    """A step's cycles that no observer needs and that only cruise run in bulk (issue
    37): the kernel counts them, and every grant's reply shows, bit for bit, what
    granting the same cycles one at a time shows; the program ends at the same cycle."""
    bulk_seen, bulk_end, bulk_cycles = _stepped_run(_GRANTS)
    singles: tuple[int, ...] = ()
    for cycles in _GRANTS:  # the same cycles, one grant per cycle, the same script
        singles += (1,) * cycles
    one_seen, one_end, one_bulk = _stepped_run(singles)
    ends = [sum(_GRANTS[:n + 1]) - 1 for n in range(len(_GRANTS))]  # a grant's last
    assert bulk_seen == [one_seen[e] for e in ends]
    assert bulk_end == one_end
    assert one_bulk == 0  # one cycle per grant: every cycle stepped and published
    assert bulk_cycles > 1500  # most of the 2 244 granted cycles only cruise


def test_granted_cycles_of_a_machine_at_rest_run_in_bulk(kernel: Kernel) -> None:
    """An idle machine's granted cycles only take the time: after the first (a whole
    cycle, as a command came before it) they run in bulk, and the reply shows the
    granted cycle with its kernel time and the channels as they were."""
    assert submit(kernel, SetFeedOverride(0, 500)) is None
    before = kernel.snapshot.channels[0]
    assert submit(kernel, StepCycles(1000)) is None
    assert kernel.snapshot.cycle == 1000
    assert kernel.snapshot.time_ns == 1000 * kernel.cycle_ns
    assert kernel.stats.bulk_cycles >= 998
    after = kernel.snapshot.channels[0]
    assert (after.state, after.switches.feed_override_command) == (before.state, 500)


def test_a_step_publishes_the_cycles_an_observer_is_due_at_and_its_last() -> None:
    """With an observer (the notification hub's hooks) due every 100 cycles, a grant
    runs in bulk between the due cycles: each due cycle and the step's last one are
    published, with the values single steps show there; the others are not."""
    k = Kernel(build_config(), StepClock(0.001), {"p.nc": _ZIGZAG}.__getitem__,
               lambda name: name == "p.nc")
    published: dict[int, tuple[Any, ...]] = {}
    k.on_cycle_end = lambda snap: published.__setitem__(snap.cycle, observed_values(snap))
    k.next_observed_ns = lambda: -(-(k.stats.cycles + 1) // 100) * 100 * k.cycle_ns
    k.start()
    try:
        assert submit(k, SelectProgram(0, "p.nc")) is None
        assert submit(k, StartProgram(0, True)) is None
        published.clear()
        assert submit(k, StepCycles(1050)) is None
    finally:
        k.close()
    due = set(range(100, 1051, 100)) | {1050}
    assert due <= set(published)
    assert len(published) < 100  # the cruising cycles in between ran unpublished
    one_seen, _end, _bulk = _stepped_run((1,) * 1050, override_at=None)
    for cycle in due:
        assert published[cycle] == one_seen[cycle - 1], cycle
