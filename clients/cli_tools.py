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
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import typer

from .cli_app import Settings, app, emit
from .errors import ClientValueError
from .units import engineering, raw_value

if TYPE_CHECKING:  # a client is made by Settings, when a command connects
    from .blocking import Client

ChannelOption = typer.Option(1, "--channel", "-c", min=1, metavar="N", help="Channel id (default 1).")

tool_app = typer.Typer(no_args_is_help=True, help="The tool list wz[i] and the active tool.")
offsets_app = typer.Typer(no_args_is_help=True,
                          help="The zero offset table np_grp[i] and the active offset.")
app.add_typer(tool_app, name="tool")
app.add_typer(offsets_app, name="offsets")

ValuesArgument = typer.Argument(..., metavar="AXIS=MM...", help="AXIS=MM, e.g. X=10 Y=-5.5")
_GROUP = re.compile(r"^(?:G(5[4-9])|(\d+))$", re.IGNORECASE)
_ASSIGNMENT = re.compile(r"^([A-Za-z])=([-+]?[0-9.]+(?:[eE][-+]?\d+)?)$")


@dataclass(frozen=True, slots=True)
class ActiveTool:
    """The tool state of a channel as its objects show it."""

    selected: int
    active: int
    d: int
    radius_mm: float
    length_mm: float


def group_name(group: int) -> str:
    """G53..G59 for groups 0..6, ``G159=i`` beyond."""
    return f"G{53 + group}" if group <= 6 else f"G159={group}"


def parse_group(text: str) -> int:
    """``G54`` -> 1 ... ``G59`` -> 6; a number is the ``np_grp`` index."""
    m = _GROUP.match(text.strip())
    if m is None:
        raise ClientValueError(f"zero offset group {text!r}: write G54..G59 or the index 1..n")
    return int(m.group(1)) - 53 if m.group(1) else int(m.group(2))


def axis_names(c: Client, channel: int) -> list[str]:
    """The channel's axis names, by axis index from 1."""
    objects = c.browse(f"ch{channel}.ax*.axis_name")
    values = c.read_many(o.name for o in objects)
    return [values[o.name] for o in objects]


def active_tool(c: Client, channel: int) -> ActiveTool:
    """T selected, T in the spindle, D, and radius and length of D."""
    names = [f"ch{channel}.{n}" for n in (
        "mc_selected_tool_r", "mc_active_tool_r", "mc_active_tool_offset_r",
        "mc_active_tool_radius_r", "mc_active_tool_length_r")]
    v = c.read_many(names)
    return ActiveTool(v[names[0]], v[names[1]], v[names[2]],
                      in_mm(c, names[3], v[names[3]]), in_mm(c, names[4], v[names[4]]))


def in_mm(c: Client, name: str, raw: float) -> float:
    """The value ``raw`` of the object ``name`` (0.1 um) in mm, by the object's scale."""
    value: float = engineering(c.describe(name), raw)
    return value


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

    def read(c: Client) -> tuple[ActiveTool, list[dict[str, Any]]]:
        size = c.read(f"ch{channel}.mc_tool_list_size_r")
        names = [f"ch{channel}.wz[{i}].{f}" for i in range(1, size + 1)
                 for f in ("valid", "radius", "laenge")]
        v = c.read_many(names)
        rows = [{"channel": channel, "wz": i, "valid": v[f"ch{channel}.wz[{i}].valid"],
                 "radius_mm": in_mm(c, f"ch{channel}.wz[{i}].radius",
                                    v[f"ch{channel}.wz[{i}].radius"]),
                 "length_mm": in_mm(c, f"ch{channel}.wz[{i}].laenge",
                                    v[f"ch{channel}.wz[{i}].laenge"])}
                for i in range(1, size + 1)]
        return active_tool(c, channel), rows

    active, rows = settings.call(read, f"tool list of channel {channel}")
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
    lengths_mm: list[tuple[str, float]] = []  # (object in 0.1 um, value in mm)
    if radius_mm is not None:
        lengths_mm.append((f"ch{channel}.wz[{d}].radius", radius_mm))
    if length_mm is not None:
        lengths_mm.append((f"ch{channel}.wz[{d}].laenge", length_mm))
    if not lengths_mm and not invalid:
        raise typer.BadParameter("give --radius, --length or --invalid")

    def write(c: Client) -> None:
        for name, value_mm in lengths_mm:
            c.write(name, raw_value(c.describe(name), value_mm))
        c.write(f"ch{channel}.wz[{d}].valid", not invalid)

    settings.call(write, f"tool list row wz[{d}] of channel {channel}")
    emit(settings, {"channel": channel, "wz": d, "ok": True},
         f"channel {channel}: wz[{d}] written")


@offsets_app.command("show")
def offsets_show(ctx: typer.Context, channel: int = ChannelOption) -> None:
    """The active zero offset, the table, and the positions in ACS and PCS."""
    settings: Settings = ctx.obj

    def read(c: Client) -> tuple[int, int, list[str], dict[str, Any], float]:
        groups = c.read(f"ch{channel}.mc_zero_offset_groups_r")
        active = c.read(f"ch{channel}.mc_active_zero_offset_r")
        axes = axis_names(c, channel)
        names = [f"ch{channel}.ax{a}.np_grp[{g}].v" for g in range(1, groups)
                 for a in range(1, len(axes) + 1)]
        names += [f"ch{channel}.ax{a}.command_position_{cs}" for a in range(1, len(axes) + 1)
                  for cs in ("acs", "pcs")]
        # positions and offsets are in 0.1 um alike: the scale of one converts them all
        scale = c.describe(f"ch{channel}.ax1.command_position_acs").scale
        return groups, active, axes, c.read_many(names), 1.0 if scale is None else scale.factor

    groups, active, axes, v, mm_per_raw = settings.call(read, f"zero offsets of channel {channel}")
    positions = {name: {cs: v[f"ch{channel}.ax{a}.command_position_{cs}"] * mm_per_raw
                        for cs in ("acs", "pcs")}
                 for a, name in enumerate(axes, start=1)}
    emit(settings, {"channel": channel, "active_group": active,
                    "active": group_name(active), "positions_mm": positions},
         f"channel {channel}: {group_name(active)} active (np_grp[{active}]); "
         + ", ".join(f"{n} ACS {_mm(p['acs'])} PCS {_mm(p['pcs'])}"
                     for n, p in positions.items()))
    for g in range(1, groups):
        offsets = {name: v[f"ch{channel}.ax{a}.np_grp[{g}].v"] * mm_per_raw
                   for a, name in enumerate(axes, start=1)}
        mark = "*" if g == active else " "
        emit(settings, {"channel": channel, "group": g, "name": group_name(g),
                        "offsets_mm": offsets},
             f"{mark} {group_name(g):<8} np_grp[{g}]  "
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
        index = parse_group(group)
        axes = [a.upper() for a in axis_names(c, channel)]
        for item in values:
            m = _ASSIGNMENT.match(item.strip())
            if m is None:
                raise ClientValueError(f"{item!r}: write AXIS=MM, e.g. X=10.5")
            letter = m.group(1).upper()
            if letter not in axes:
                raise ClientValueError(f"{letter}: channel {channel} has the axes "
                                       f"{', '.join(axes)}")
            a = axes.index(letter) + 1
            target = f"ch{channel}.ax{a}.np_grp[{index}].v"
            c.write(target, raw_value(c.describe(target), float(m.group(2))))

    settings.call(write, f"zero offset {group} of channel {channel}")
    emit(settings, {"channel": channel, "group": group, "ok": True},
         f"channel {channel}: zero offset {group} written")
