"""``V.G.NP[j].V.<axis> = value`` and ``V.G.NP[j].V[i] = value``: an NC program writes a
zero offset (mm).

ISG (programming manual, "Enhanced zero offset variables",
tf5200_programming_manual/206493195.html): "Write access via the V.G.NP[j] ... variables
remains effective until the next list interpretation"; the "Zero offsets (G53/G54/...G59)"
page writes ``V.G.NP[1].V.X=10`` before ``G54``. Writing the group in effect is ISG's error
14421, "Changing an active zero offset (G54-G59) not permitted"
(tf5200_diagnosis/1208284683.html).

Like every V.G. variable the write happens where the decoder is, ahead of the path: the
blocks decoded after it use the new value. The live table (what the objects show, what
the next program starts with, what the operator data store keeps) changes when the next
block is interpolated: the decoder feed hands the writes to the kernel with that block's
tooling view (``ToolingTables.nc_zero_offsets``). Until then the run decodes on a copy
of the tables of its own, so a syntax check or a dry run changes nothing.
"""

from __future__ import annotations

import math
from dataclasses import replace

from .errors import NcErrorId
from .modal import ModalState
from .source import LogicalLine
from .tool_data import TABLE_VALUE_MAX_01UM, ZeroOffsetTable, ZeroOffsetWrite
from .variables import Value, Variable, VariableFault

__all__ = ["ZeroOffsetWrite", "with_writes", "write_zero_offset"]


def write_zero_offset(modal: ModalState, axes: tuple[str, ...], variable: Variable,
                      indices: tuple[int, ...], value: Value, line: LogicalLine, pos: int
                      ) -> None:
    """Write one element of ``variable`` (``V.G.NP.V.<axis>`` indexed by group, or
    ``V.G.NP.V`` by group and axis, as the decoder provides it for reading) into the
    run's copy of the tables; an ``NcError`` at ``pos`` for a bad index, type or value,
    or for the group in effect."""
    try:
        variable.set(value, indices)  # the index and type checks of a read, and REAL64
    except VariableFault as fault:
        raise line.error(fault.err_id, fault.message, pos) from None
    group = indices[0]
    axis = indices[1] if len(indices) == 2 else axes.index(variable.name.rsplit(".", 1)[1])
    if group == 0:
        raise line.error(NcErrorId.ARRAY_INDEX_OUT_OF_RANGE,
                         f"{variable.name}[0]: group 0 is G53, no offset (the twin has no "
                         "G53 data block, P-ZERO-00001)", pos)
    if group == modal.zero_offset_group:
        raise line.error(NcErrorId.ZERO_OFFSET_ACTIVE,
                         f"zero offset group {group} (G{53 + group if group <= 6 else 159}) "
                         "is in effect: write it while another group (or G53) is selected",
                         pos)
    value_mm = float(variable.get(indices))
    value_01um = value_mm * 10_000.0
    if not math.isfinite(value_01um) or abs(value_01um) > TABLE_VALUE_MAX_01UM:
        raise line.error(NcErrorId.VALUE_OUT_OF_RANGE,
                         f"zero offset {value_mm:g} mm is outside +-214748.3647 mm", pos)
    tables = modal.tooling
    written = {(g, a): v for g, a, v in tables.nc_zero_offsets}
    written[(group, axis)] = value_01um
    modal.tooling = replace(
        tables,
        zero_offsets=tables.zero_offsets.with_offset(group, axis, len(axes), value_01um),
        nc_zero_offsets=tuple((g, a, v) for (g, a), v in written.items()),
    )


def with_writes(table: ZeroOffsetTable, writes: tuple[ZeroOffsetWrite, ...], axis_count: int
                ) -> ZeroOffsetTable:
    """``table`` with ``writes`` in it (``table`` itself when it holds them already: a
    view is shown again at every change of T, D or the group)."""
    for group, axis, value_01um in writes:
        if table.offset_01um(group, axis) != value_01um:
            table = table.with_offset(group, axis, axis_count, value_01um)
    return table
