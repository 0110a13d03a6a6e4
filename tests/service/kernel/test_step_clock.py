"""The step clock in-process: cycles run only when granted, commands between cycles are
applied at once, and the edges of a step (a second step, STOP, shutdown) are answered."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.clock import VirtualClock
from cnc_objects.service.kernel.commands import RefusalReason, SetFeedOverride
from cnc_objects.service.kernel.kernel import Control, ControlCommand, Kernel
from cnc_objects.service.kernel.step_clock import StepClock, StepCycles
from tests.service.test_kernel import Applied, submit


@pytest.fixture
def kernel() -> Iterator[Kernel]:
    k = Kernel(build_config(), StepClock(0.001, max_cycles=1000))
    k.start()
    yield k
    k.close()


def test_no_cycle_runs_until_granted_and_a_step_runs_exactly_its_cycles(kernel: Kernel) -> None:
    assert submit(kernel, SetFeedOverride(0, 500)) is None  # applied without a cycle
    assert kernel.snapshot.cycle == 0
    assert kernel.snapshot.channels[0].feed_override_command == 500
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
