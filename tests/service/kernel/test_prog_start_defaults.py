"""Start-up defaults (ISG channel list ``prog_start.*``): the FCT-C15 example as printed.

FCT-C15 section 2.4 moves channel 2 with the manual block ``G91 Y10``: no F and no G01 of
its own. It runs because channel 2's P-CHAN-00099 ``prog_start.feedrate`` gives a block
without F its feed (the embedded machine sets 1000 mm/min there); with 0 the same block
is the NC error "no feed". The real kernel on the virtual clock.
"""

from __future__ import annotations

from typing import Any

import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.commands import ManualBlock, SetExecutionMode, SetSuspendCommand
from cnc_objects.service.kernel.nc.errors import NcErrorId
from cnc_objects.service.kernel.state import LinkState, Snapshot
from cnc_objects.service.machine_config import DEFAULT_MACHINE
from tests.support.kernel import KernelHarness

EXTENDED_MDI = 0x80
INCR = 10_000  # 0.1 um per mm


def _mdi(h: KernelHarness, ci: int, text: str, done_before: int) -> Snapshot:
    assert h.command(ManualBlock(ci, text)) is None
    return h.wait_for(
        lambda s: s.channels[ci].block.manual_blocks_done > done_before
        and s.channels[ci].path.path_velocity_mm_s == 0.0
        or s.channels[ci].state == ChannelState.ERROR
    )


def _suspend(h: KernelHarness, ci: int, on: bool) -> None:
    assert h.command(SetSuspendCommand(ci, on)) is None
    h.wait_for(lambda s: s.channels[ci].suspend.output_suspended == on)


def _run_example(h: KernelHarness) -> Snapshot:
    """Steps 1..4 of FCT-C15 section 2.4, exactly as printed; the snapshot after step 4."""
    for ci in (0, 1):
        assert h.command(SetExecutionMode(ci, EXTENDED_MDI)) is None
    _mdi(h, 0, "G01 G90 X20 Y20 F100", 0)  # 1.
    _suspend(h, 0, True)  # 2.
    _suspend(h, 1, False)  # 3.
    h.wait_for(lambda s: all(a.link_state == LinkState.LINKED for a in s.channels[1].axes))
    return _mdi(h, 1, "G91 Y10", 0)  # 4.


def test_the_example_runs_as_printed() -> None:
    with KernelHarness() as h:
        s = _run_example(h)
        ch2 = s.channels[1]
        assert ch2.state != ChannelState.ERROR, ch2.errors.entries
        assert s.physical_axes[1].command_position_01um == 30 * INCR  # Y 20 -> 30
        assert ch2.axes[1].command_position_01um == 30 * INCR
        _suspend(h, 0, False)  # 5.
        _suspend(h, 1, True)  # 6.
        h.wait_for(lambda s: all(a.link_state == LinkState.LINKED for a in s.channels[0].axes))


def _config(feedrate: float) -> Any:
    """The embedded machine with channel 2's prog_start.feedrate set to ``feedrate``."""
    channels = [dict(c) for c in DEFAULT_MACHINE["channels"]]
    channels[1]["prog_start"] = {"feedrate": feedrate}
    return build_config({"channels": channels})


def test_without_the_start_feed_step_4_is_the_no_feed_error() -> None:
    with KernelHarness(config=_config(0.0)) as h:
        s = _run_example(h)
        ch2 = s.channels[1]
        assert ch2.state == ChannelState.ERROR
        errors = [(e.id, e.line, e.column) for e in ch2.errors.entries]
        assert errors == [(NcErrorId.NO_FEED, 1, 5)]  # at Y10


@pytest.mark.parametrize("feed", [-1.0, 1e8])
def test_a_start_feed_out_of_range_is_refused(feed: float) -> None:
    with pytest.raises(ValueError, match="prog_start.feedrate"):
        _config(feed)
