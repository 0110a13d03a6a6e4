"""What the objects show as the active zero offset, D and PCS shift: the block being
interpolated, not the decoder's look-ahead state (issue 39, departure 10)."""

from __future__ import annotations

from cnc_objects.protocol.units import UM01_PER_MM
from cnc_objects.service.kernel.commands import StartProgram
from cnc_objects.service.kernel.commands_tooling import SetZeroOffset
from tests.support.kernel import KernelHarness


def test_at_a_stop_the_objects_show_the_offset_of_the_block_that_ran() -> None:
    """G54 (Z 50 mm) then M0; the decoder has decoded G53 beyond the stop already. At the
    stop the machine Z is 60 and the shown offset is G54's: PCS Z = 60 - 50 = 10."""
    program = "G54 G0 X0 Y0 Z10\nM0\nG53\nG0 Z20\nG0 X1\nG0 X2\nM30\n"
    with KernelHarness() as h:
        assert h.command(SetZeroOffset(0, 1, 2, 50.0 * UM01_PER_MM)) is None
        h.start(program)
        snap = h.wait_for(lambda s: s.channels[0].program.waiting_for_start)
        ch = snap.channels[0]
        assert ch.axes[2].position_mm == 60.0
        assert ch.tooling.zero_offset_group == 1
        assert ch.tooling.shift_mm[2] == 50.0
        assert h.command(StartProgram(0, False)) is None
        assert h.command(StartProgram(0, True)) is None
        run = h.wait()
        assert run.channel.tooling.zero_offset_group == 0
        assert run.channel.tooling.shift_mm[2] == 0.0
        assert run.channel.axes[2].position_mm == 20.0
