"""What the objects show as the active zero offset, D and PCS shift: the block being
interpolated, not the decoder's look-ahead state (issue 39, departure 10)."""

from __future__ import annotations

from cnc_objects.protocol.units import UM01_PER_MM
from cnc_objects.protocol.values import ExecutionMode
from cnc_objects.service.kernel.commands import SetExecutionMode, StartProgram
from cnc_objects.service.kernel.commands_tooling import SetZeroOffset
from tests.support.kernel import KernelHarness

SYNCHK, MACHINE_LOCK = ExecutionMode.SYNCHK, ExecutionMode.MACHINE_LOCK
PROD_TIME = ExecutionMode.PROD_TIME


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


def test_a_zero_offset_written_by_the_program_reaches_the_table_with_the_path() -> None:
    """``V.G.NP[1].V.X = 12.5`` (issue 39, departure 9): the decoder has decoded the write
    (and G55's blocks beyond the stop) before the path gets there; the objects' table shows
    it from the block after the write on, and the next program starts with it (ISG: until
    the list is read again)."""
    program = ("G55 G0 X0 Y0 Z0\nM0\nV.G.NP[1].V.X = 12.5\nG54 G0 X0\nM0\n"
               "V.G.NP[2].V.Y = -3\nG55 G0 Y0\nM30\n")
    with KernelHarness() as h:
        h.start(program)
        snap = h.wait_for(lambda s: s.channels[0].program.waiting_for_start)
        assert snap.channels[0].tooling.zero_offsets.offset_mm(1, 0) == 0.0  # not yet
        assert h.command(StartProgram(0, False)) is None
        assert h.command(StartProgram(0, True)) is None
        snap = h.wait_for(lambda s: s.channels[0].program.waiting_for_start
                          and s.channels[0].tooling.zero_offset_group == 1)
        ch = snap.channels[0]
        assert ch.tooling.zero_offsets.offset_mm(1, 0) == 12.5
        assert ch.tooling.zero_offsets.offset_mm(2, 1) == 0.0  # decoded, not reached
        assert ch.axes[0].position_mm == 12.5
        assert h.command(StartProgram(0, False)) is None
        assert h.command(StartProgram(0, True)) is None
        run = h.wait()
        assert run.channel.tooling.zero_offsets.offset_mm(2, 1) == -3.0
        assert run.channel.axes[1].position_mm == -3.0
        assert h.run("G54 G0 X1\nM30\n", "next.nc").channel.axes[0].position_mm == 13.5


def test_a_syntax_check_and_a_production_time_run_leave_the_table_alone() -> None:
    """The write is decoded (and checked) but the tables are the operator's: a check or
    a simulation changes nothing."""
    program = "V.G.NP[3].V.Z = 7\nG56 G0 Z0\nM30\n"
    with KernelHarness() as h:
        for mode in (SYNCHK | MACHINE_LOCK, PROD_TIME):
            assert h.command(SetExecutionMode(0, mode)) is None
            run = h.run(program, f"mode{mode}.nc")
            assert run.channel.errors.entries == ()
            assert run.channel.tooling.zero_offsets.offset_mm(3, 2) == 0.0
        assert h.command(SetExecutionMode(0, 0)) is None
        run = h.run(program, "real.nc")
        assert run.channel.tooling.zero_offsets.offset_mm(3, 2) == 7.0
        assert run.channel.axes[2].position_mm == 7.0
