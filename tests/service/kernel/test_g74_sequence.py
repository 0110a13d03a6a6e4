"""``G74`` with a homing sequence (issue 39, departure 8): ``G74 X2 Y3 Z1`` homes Z,
then X, then Y, axes with the same number together (ISG programming manual,
"Programmable homing (G74)"); bad places give ISG's error ids with file, line, column.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from cnc_objects.protocol.values import ChannelState
from cnc_objects.service.kernel.commands import ResetChannel
from tests.support.kernel import KernelHarness
from tests.support.manual_machine import REF_MM, machine


@pytest.fixture
def k() -> Iterator[KernelHarness]:
    with KernelHarness(config=machine()) as harness:
        yield harness


def _steps(k: KernelHarness) -> list[tuple[tuple[bool, ...], tuple[float, ...]]]:
    """Record every change of the referenced flags of channel 1 with the axis
    positions of that cycle (on the cycle thread, until the next watch)."""
    seen: list[tuple[tuple[bool, ...], tuple[float, ...]]] = []

    def record(snap: Any) -> bool:
        ch = snap.channels[0]
        flags = tuple(m.referenced for m in ch.manual)
        if not seen or seen[-1][0] != flags:
            seen.append((flags, tuple(a.position_mm for a in ch.axes)))
        return False

    k.watch(record)
    return seen


def test_g74_homes_the_axes_in_the_order_of_their_numbers(k: KernelHarness) -> None:
    k.mdi("G01 X-2 Y4 Z1 F600")
    seen = _steps(k)
    run = k.run("N10 G74 X2 Y3 Z1\nM30\n")
    assert run.channel.state == ChannelState.READY, run.channel.errors.entries
    flags = [f for f, _ in seen]
    assert flags == [(False, False, False), (False, False, True), (True, False, True),
                     (True, True, True)]
    # Z referenced at 0 while X and Y had not moved; X at its reference while Y had not
    # (the cycle that shows a group referenced is the first of the next: 1 um at most)
    assert seen[1][1] == pytest.approx((-2.0, 4.0, 0.0), abs=0.002)
    assert seen[2][1] == pytest.approx((REF_MM, 4.0, 0.0), abs=0.002)
    assert run.positions_mm == pytest.approx((REF_MM, 0.0, 0.0))


def test_g74_axes_with_the_same_number_home_together(k: KernelHarness) -> None:
    k.mdi("G01 X-2 Y4 Z1 F600")
    seen = _steps(k)
    run = k.run("N10 G74 Z1 X2 Y2\nN20 G01 X5 F600\nM30\n")
    assert run.channel.state == ChannelState.READY, run.channel.errors.entries
    assert [f for f, _ in seen] == [(False, False, False), (False, False, True),
                                    (True, True, True)]
    assert seen[1][1] == pytest.approx((-2.0, 4.0, 0.0), abs=0.002)
    assert run.positions_mm == pytest.approx((5.0, 0.0, 0.0))


def test_g74_sequence_in_a_manual_block(k: KernelHarness) -> None:
    run = k.mdi("G74 Y2 X1")
    assert run.channel.state == ChannelState.READY, run.channel.errors.entries
    assert [m.referenced for m in run.channel.manual] == [True, True, False]
    assert run.positions_mm[0] == pytest.approx(REF_MM)


@pytest.mark.parametrize(("text", "error_id", "column", "words"), [
    ("G74", 20136, 1, "needs the axes"),
    ("G74 X1 X2", 20111, 8, "twice"),
    ("G74 X0", 20816, 5, "whole number"),
    ("G74 X-1 Y1", 20816, 5, "whole number"),
    ("G74 X1.5", 20816, 5, "whole number"),
])
def test_bad_g74_blocks_stop_with_isg_ids(k: KernelHarness, text: str, error_id: int,
                                         column: int, words: str) -> None:
    k.command(ResetChannel(0, True))
    run = k.run(f"N10 G01 X1 F600\n{text}\nM30\n", name="bad.nc")
    assert run.channel.state == ChannelState.ERROR
    [error] = run.channel.errors.entries
    assert (error.id, error.file, error.line, error.column) == (error_id, "bad.nc", 2, column)
    assert words in error.text
    assert run.positions_mm[0] == pytest.approx(1.0)  # the blocks before it ran
