"""Tools and zero offsets in the decoder: the program shift on absolute positions, the
plane's tool axis, #CS on top of the shift, the hot path and the general path alike."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from cnc_objects.service.kernel.nc import ModalState, NcErrorId
from cnc_objects.service.kernel.nc.tool_data import (
    ToolData,
    ToolingTables,
    ToolTable,
    ZeroOffsetTable,
)

from .support import decode, ends, error_of, slow


def modal_with(offsets: dict[int, tuple[float, ...]] | None = None,
               tools: dict[int, ToolData] | None = None, change_s: float = 0.0) -> ModalState:
    """A modal state whose channel tables hold ``offsets`` and ``tools``."""
    table = ToolTable(tools or {1: ToolData.of_mm(2.5)}, 9)
    tables = ToolingTables(table, ZeroOffsetTable.of_mm(10, offsets or {}), change_s)
    return ModalState(tooling=tables)


LENGTH = {1: ToolData.of_mm(2.5), 4: ToolData.of_mm(3.0, 100.0)}


@pytest.mark.parametrize("as_text", [lambda t: t, slow], ids=["hot path", "general path"])
def test_zero_offset_and_tool_length_shift_absolute_positions(as_text) -> None:
    program = "G54\nD4\nG0 X1 Y2 Z3\nG1 X5 F100\nG91 X1\nG90 G53 D0 X0 Y0 Z0\nM30"
    got = ends(as_text(program), modal=modal_with({1: (10.0, 20.0, 30.0)}, LENGTH))
    assert got == [(11.0, 22.0, 133.0), (15.0, 22.0, 133.0), (16.0, 22.0, 133.0),
                   (0.0, 0.0, 0.0)]


@pytest.mark.parametrize(("plane", "axis"), [(17, 2), (18, 1), (19, 0)])
def test_the_tool_length_acts_along_the_tool_axis_of_the_plane(plane, axis) -> None:
    [end] = ends(f"G{plane} D4 G0 X0 Y0 Z0\nM30", modal=modal_with(tools=LENGTH))
    expected = [0.0, 0.0, 0.0]
    expected[axis] = 100.0
    assert end == tuple(expected)


def test_unprogrammed_axes_keep_their_machine_position() -> None:
    got = ends("G0 X1 Y1 Z1\nG54\nG0 X2\nM30", modal=modal_with({1: (10.0, 20.0, 30.0)}))
    assert got == [(1.0, 1.0, 1.0), (12.0, 1.0, 1.0)]


def test_a_machining_coordinate_system_lies_on_the_zero_offset() -> None:
    program = "G54\n#CS ON [1, 0, 0, 0, 0, 90]\nG0 X1 Y0 Z0\n#CS OFF\nM30"
    [end] = ends(program, modal=modal_with({1: (10.0, 0.0, 0.0)}))
    assert end == pytest.approx((11.0, 1.0, 0.0))


def test_g159_selects_further_groups() -> None:
    modal = modal_with({8: (0.0, -4.0, 0.0)})
    assert ends("G159=8 G0 Y1\nM30", modal=modal) == [(0.0, -3.0, 0.0)]
    assert modal.zero_offset_group == 8


def test_m6_takes_the_tool_and_waits_the_change_time() -> None:
    modal = modal_with(change_s=1.5)
    blocks = decode("T1\nM6\nM30", modal=modal)
    assert [(b.tool, b.m_functions, b.dwell_s) for b in blocks[:2]] == [
        (1, (), 0.0), (None, (6,), 1.5)]
    assert modal.spindle_tool == 1


@pytest.mark.parametrize(
    ("program", "error_id", "column"),
    [("T5", NcErrorId.UNKNOWN_TOOL, 1), ("M6", NcErrorId.TOOL_CHANGE_WITHOUT_TOOL, 1),
     ("G0 G159=10", NcErrorId.ZERO_OFFSET_INDEX_RANGE, 4),
     ("G159=-1", NcErrorId.ZERO_OFFSET_INDEX_FORMAT, 1),
     ("G159=2 G54", NcErrorId.ZERO_OFFSETS_TWICE, 8)],
)
def test_bad_words(program: str, error_id: int, column: int) -> None:
    error = error_of(program + "\nM30", modal=modal_with())
    assert (error.id, error.line, error.column) == (error_id, 1, column)


def test_a_failing_block_leaves_the_tool_and_the_offset_as_they_were() -> None:
    modal = modal_with()
    error_of("T1 M6\nG55\nG54 G159=20\nM30", modal=modal)
    assert (modal.spindle_tool, modal.zero_offset_group) == (1, 2)


def test_a_table_from_radii_accepts_every_tool() -> None:
    """Decoders given plain radii (syntax tools, tests) do not check T numbers."""
    blocks = decode("T23 M6\nM30")
    assert blocks[0].tool == 23


# ---------------------------------------------- V.G.NP: the zero offsets from NC (issue 39)


@pytest.mark.parametrize("as_text", [lambda t: t, slow], ids=["hot path", "general path"])
def test_a_program_reads_the_zero_offset_table_per_axis_name_and_index(
        as_text: Callable[[str], str]) -> None:
    """V.G.NP[j].V.<axis> and V.G.NP[j].V[i] (index i from 0): offset j (1 = G54) in mm."""
    program = "G0 XV.G.NP[1].V.X YV.G.NP[2].V[1] Z[V.G.NP[1].V.Z + 1]\nM30"
    modal = modal_with({1: (10.0, 20.0, 30.0), 2: (0.0, -7.5, 0.0)})
    assert ends(as_text(program), modal=modal) == [(10.0, -7.5, 31.0)]


@pytest.mark.parametrize(
    ("program", "error_id", "column"),
    [("G0 XV.G.NP[10].V.X", NcErrorId.ARRAY_INDEX_OUT_OF_RANGE, 5),
     ("G0 XV.G.NP[1].V.Q", NcErrorId.UNDECLARED_VARIABLE, 5),
     ("G0 XV.G.NP[1].V[3]", NcErrorId.ARRAY_INDEX_OUT_OF_RANGE, 5),
     ("V.G.NP[10].V.X = 1", NcErrorId.ARRAY_INDEX_OUT_OF_RANGE, 1),
     ("V.G.NP[0].V.X = 1", NcErrorId.ARRAY_INDEX_OUT_OF_RANGE, 1),
     ("V.G.NP[1].V.X = \"A\"", NcErrorId.TYPE_MISMATCH, 1),
     ("V.G.NP[1].V.X = 300000", NcErrorId.VALUE_OUT_OF_RANGE, 1),
     ("G54\nV.G.NP[1].V[0] = 1", NcErrorId.ZERO_OFFSET_ACTIVE, 1)],
)
def test_bad_zero_offset_variables(program: str, error_id: int, column: int) -> None:
    """Out of range, an axis the channel lacks, a bad value, and a write of the group in
    effect (ISG 14421): ISG ids with their line and column."""
    error = error_of(program + "\nM30", modal=modal_with({1: (10.0, 20.0, 30.0)}))
    assert (error.id, error.line, error.column) == (error_id, program.count("\n") + 1, column)


@pytest.mark.parametrize("as_text", [lambda t: t, slow], ids=["hot path", "general path"])
def test_a_program_writes_a_zero_offset_for_the_blocks_after_it(
        as_text: Callable[[str], str]) -> None:
    """ISG's example (programming manual, G53/G54..G59): ``V.G.NP[1].V.X=10``, then G54
    and ``G0 X=100`` moves to 110; the index form writes one axis by number; the
    channel's own table is not touched by the decoder (the kernel applies the writes when
    the path gets there)."""
    program = ("V.G.NP[1].V.X = 10\nV.G.NP[1].V[1] = V.G.NP[1].V.X * 2\nG54\n"
               "G0 X=100 Y0 Z0\nG55\nV.G.NP[1].V.Z = -5\nG54 G0 Z0\nM30")
    modal = modal_with({1: (1.0, 2.0, 3.0)})
    live = modal.tooling
    before = live.zero_offsets
    assert ends(as_text(program), modal=modal) == [(110.0, 20.0, 3.0), (110.0, 20.0, -5.0)]
    assert live.zero_offsets is before and live.nc_zero_offsets == ()
    assert modal.tooling.nc_zero_offsets == ((1, 0, 100_000.0), (1, 1, 200_000.0),
                                             (1, 2, -50_000.0))
