"""A kernel at rest: its cycles only take the time (issue 36 point 10, the idle service's
CPU), and every value a client can see is the one of a kernel that does every cycle's
whole work (``rest_when_idle=False``, the reference), cycle for cycle.

The script drives one kernel through what ends and starts a rest: manual blocks (a
spindle that ramps up and down after its block, an M function), overrides, suspending
the axis output and taking it back, a RESET. Both kernels step on the virtual clock
(every cycle published); the script's commands are submitted at the end of fixed cycles,
so both apply them at the start of the same cycle.
"""

from __future__ import annotations

import threading
from typing import Any

import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.clock import VirtualClock
from cnc_objects.service.kernel.commands import (
    ManualBlock,
    SetFeedOverride,
    SetSuspendCommand,
    SetSuspendEnable,
)
from cnc_objects.service.kernel.commands_technology import SetSpindleOverride
from cnc_objects.service.kernel.kernel import Control, ControlCommand, Kernel
from cnc_objects.service.kernel.state import Snapshot

_TIMEOUT_S = 60.0
# cycle -> the commands submitted at its end (applied at the start of the next one)
SCRIPT: dict[int, list[Any]] = {
    20: [ManualBlock(0, "M3 S2000")],
    400: [SetSpindleOverride(0, 500)],
    700: [ManualBlock(0, "M5")],
    900: [SetFeedOverride(0, 500), ManualBlock(0, "M8")],
    950: [ManualBlock(1, "M8")],  # channel 2 starts with its output suspended: it waits
    1000: [SetSuspendEnable(0, True), SetSuspendCommand(0, True)],
    1100: [SetSuspendCommand(0, False)],
    1200: [ManualBlock(0, "G91 G1 X1 F6000")],
    1400: [ControlCommand(Control.RESET)],
}
END_CYCLE = 1600


def _seen(snap: Snapshot) -> tuple[Any, ...]:
    """Everything a client reads of one cycle, but the wall-clock figures (wall time, the
    cycle's execution time, jitter), which no two runs share."""
    stats = snap.stats
    return (snap.cycle, snap.time_ns, stats.cycles, stats.running, snap.channels,
            snap.physical_axes)


def _record(rest_when_idle: bool) -> tuple[dict[int, tuple[Any, ...]], set[int]]:
    """Run the script; what every cycle published, and the cycles that rested (their
    snapshot shares the channels and drives of the cycle before)."""
    config = build_config()
    kernel = Kernel(config, VirtualClock(config.cycle_ms / 1000.0, event_speed=False),
                    rest_when_idle=rest_when_idle)
    seen: dict[int, tuple[Any, ...]] = {}
    rested: set[int] = set()
    last: list[Snapshot] = []
    done = threading.Event()
    refusals: list[Any] = []

    def answer(refusal: Any) -> None:
        if refusal is not None:
            refusals.append(refusal)

    def on_cycle_end(snap: Snapshot) -> None:
        if done.is_set():
            return
        if last and snap.channels is last[0].channels \
                and snap.physical_axes is last[0].physical_axes:
            rested.add(snap.cycle)
        last[:] = [snap]
        seen[snap.cycle] = _seen(snap)
        for command in SCRIPT.get(snap.cycle, ()):
            kernel.submit(command, answer)
        if snap.cycle >= END_CYCLE:
            done.set()

    kernel.on_cycle_end = on_cycle_end
    kernel.start()
    try:
        assert done.wait(_TIMEOUT_S), "the script did not end"
    finally:
        kernel.close()
    assert not refusals, refusals
    return seen, rested


@pytest.fixture(scope="module")
def reference() -> tuple[dict[int, tuple[Any, ...]], set[int]]:
    return _record(rest_when_idle=False)


def test_every_cycle_shows_what_the_whole_work_shows(
    reference: tuple[dict[int, tuple[Any, ...]], set[int]],
) -> None:
    expected, _ = reference
    seen, rested = _record(rest_when_idle=True)
    assert sorted(seen) == sorted(expected) == list(range(1, max(seen) + 1))
    for cycle in sorted(expected):
        assert seen[cycle] == expected[cycle], f"cycle {cycle} differs"
    # at rest before the first command, once the spindle stands again, before the
    # suspend (channel 2 waits for its axes: not at rest) and after the RESET
    assert {19, 699, 899, 1599} <= rested, sorted(rested)


def test_a_kernel_at_rest_republishes_its_channels_and_drives(
    reference: tuple[dict[int, tuple[Any, ...]], set[int]],
) -> None:
    """Resting cycles publish the previous cycle's frozen channels and drives (nothing
    is copied); the reference never rests, and its values are the same (test above)."""
    _, rested_without = reference
    assert not rested_without
    _, rested = _record(rest_when_idle=True)
    assert len(rested) > END_CYCLE // 4, len(rested)
