"""``cnc tool`` and ``cnc offsets``: the tool list and the zero offset table of a channel,
read and written through their objects (docs/tools-offsets.md).

    cnc tool show [--channel N] [--all]
    cnc tool set D [--radius MM] [--length MM] [--invalid] [--channel N]
    cnc offsets show [--channel N]
    cnc offsets set GROUP AXIS=MM [AXIS=MM ...] [--channel N]

Lengths are given and shown in mm; the objects carry 0.1 um, converted by the scale the
service gives for each object (clients/units.py). ``GROUP`` is G54..G59, or
the index of ``np_grp`` (1..n-1; 7.. are the groups of ``G159 = i``). A value the
service refuses (a negative radius, an offset beyond the position range) ends the
command with exit 1 and the service's sentence.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import typer

from ..errors import ClientValueError
from .app import Settings, app, emit

if TYPE_CHECKING:  # a client is made by Settings, when a command connects
    from ..blocking import Client
    from ..tooling_ops import ActiveTool, ToolRow, ZeroOffsets

ChannelOption = typer.Option(1, "--channel", "-c", min=1, metavar="N", help="Channel id (default 1).")

tool_app = typer.Typer(no_args_is_help=True, help="The tool list wz[i] and the active tool.")
offsets_app = typer.Typer(no_args_is_help=True,
                          help="The zero offset table np_grp[i] and the active offset.")
app.add_typer(tool_app, name="tool")
app.add_typer(offsets_app, name="offsets")

ValuesArgument = typer.Argument(..., metavar="AXIS=MM...", help="AXIS=MM, e.g. X=10 Y=-5.5")
_ASSIGNMENT = re.compile(r"^([A-Za-z])=([-+]?[0-9.]+(?:[eE][-+]?\d+)?)$")


def _group_name(group: int) -> str:
    from ..tooling_ops import group_name  # the client library, once a command runs

    return group_name(group)


def _mm(value: float) -> str:
    return f"{value:.4f}"


@tool_app.command("show")
def tool_show(
    ctx: typer.Context,
    channel: int = ChannelOption,
    show_all: bool = typer.Option(False, "--all", help="Show empty rows too."),
) -> None:
    """The active tool (T, D, radius, length) and the rows of the tool list."""
    settings: Settings = ctx.obj

    def read(c: Client) -> tuple[ActiveTool, list[ToolRow]]:
        return c.active_tool(channel), c.tools(channel)

    active, tools = settings.call(read, f"tool list of channel {channel}")
    rows = [{"channel": channel, "wz": t.wz, "valid": t.valid, "radius_mm": t.radius_mm,
             "length_mm": t.length_mm} for t in tools]
    emit(settings, {"channel": channel, "selected_tool": active.selected,
                    "active_tool": active.active, "d": active.d,
                    "radius_mm": active.radius_mm, "length_mm": active.length_mm},
         f"channel {channel}: tool T{active.active} in the spindle (T{active.selected} "
         f"selected), D{active.d}: radius {_mm(active.radius_mm)} mm, "
         f"length {_mm(active.length_mm)} mm")
    for row in rows:
        if row["valid"] or show_all:
            emit(settings, row, f"wz[{row['wz']:>3}] {'valid' if row['valid'] else 'empty'}  "
                                f"radius {_mm(row['radius_mm']):>10} mm  "
                                f"laenge {_mm(row['length_mm']):>10} mm")


@tool_app.command("set")
def tool_set(
    ctx: typer.Context,
    d: int = typer.Argument(..., min=1, metavar="D", help="Row of the tool list (T and D number)."),
    radius_mm: float = typer.Option(None, "--radius", help="Tool radius (mm, >= 0)."),
    length_mm: float = typer.Option(None, "--length", help="Tool length (mm)."),
    invalid: bool = typer.Option(False, "--invalid", help="Empty the row (T/D refuse it)."),
    channel: int = ChannelOption,
) -> None:
    """Write a row of the tool list: radius and length, and the row valid (or empty it
    with --invalid)."""
    settings: Settings = ctx.obj
    if radius_mm is None and length_mm is None and not invalid:
        raise typer.BadParameter("give --radius, --length or --invalid")

    def write(c: Client) -> None:
        c.set_tool(d, radius_mm, length_mm, valid=not invalid, channel=channel)

    settings.call(write, f"tool list row wz[{d}] of channel {channel}")
    emit(settings, {"channel": channel, "wz": d, "ok": True},
         f"channel {channel}: wz[{d}] written")


@offsets_app.command("show")
def offsets_show(ctx: typer.Context, channel: int = ChannelOption) -> None:
    """The active zero offset, the table, and the positions in ACS and PCS."""
    settings: Settings = ctx.obj

    def read(c: Client) -> ZeroOffsets:
        return c.zero_offsets(channel)

    table = settings.call(read, f"zero offsets of channel {channel}")
    active, positions = table.active_group, table.positions_mm
    emit(settings, {"channel": channel, "active_group": active,
                    "active": _group_name(active), "positions_mm": positions},
         f"channel {channel}: {_group_name(active)} active (np_grp[{active}]); "
         + ", ".join(f"{n} ACS {_mm(p['acs'])} PCS {_mm(p['pcs'])}"
                     for n, p in positions.items()))
    for g, offsets in table.groups.items():
        mark = "*" if g == active else " "
        emit(settings, {"channel": channel, "group": g, "name": _group_name(g),
                        "offsets_mm": offsets},
             f"{mark} {_group_name(g):<8} np_grp[{g}]  "
             + "  ".join(f"{n} {_mm(x):>10}" for n, x in offsets.items()))


@offsets_app.command("set")
def offsets_set(
    ctx: typer.Context,
    group: str = typer.Argument(..., metavar="GROUP", help="G54..G59, or the np_grp index (G159 = i)."),
    values: list[str] = ValuesArgument,
    channel: int = ChannelOption,
) -> None:
    """Write zero offsets of one group (mm per axis)."""
    settings: Settings = ctx.obj

    def write(c: Client) -> None:
        offsets_mm: dict[str, float] = {}
        for item in values:
            m = _ASSIGNMENT.match(item.strip())
            if m is None:
                raise ClientValueError(f"{item!r}: write AXIS=MM, e.g. X=10.5")
            offsets_mm[m.group(1).upper()] = float(m.group(2))
        c.set_zero_offset(group, offsets_mm, channel)

    settings.call(write, f"zero offset {group} of channel {channel}")
    emit(settings, {"channel": channel, "group": group, "ok": True},
         f"channel {channel}: zero offset {group} written")
