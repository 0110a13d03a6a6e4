"""``cnc tool export/import`` and ``cnc offsets export/import``: a channel's tool list or
zero offset table to and from an operator data file (``objects.operator_data``, the
format the service keeps them in; docs/manual.md, "Operator data file").

    cnc tool export FILE [--channel N]       cnc offsets export FILE [--channel N]
    cnc tool import FILE [--channel N]       cnc offsets import FILE [--channel N]

``FILE`` ``-`` is standard output / input. An import makes the table equal to the file's:
the rows (groups) it lists are written, the others emptied; the file is checked whole
before anything is written, and a value the service refuses ends the import with exit 1
and the service's sentence (the rows written before it stay written).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from cnc_objects.objects.operator_data import (
    ChannelData,
    OffsetGroup,
    OperatorData,
    OperatorDataError,
    ToolRow,
    dumps,
    loads,
)

from .. import names
from ..errors import ClientValueError
from ..units import engineering, raw_value
from .app import Settings, emit, fail
from .tools import ChannelOption, offsets_app, tool_app

if TYPE_CHECKING:  # a client is made by Settings, when a command connects
    from ..blocking import Client

def in_mm(c: Client, name: str, raw: float) -> float:
    """The value ``raw`` of the object ``name`` (0.1 um) in mm, by the object's scale."""
    value: float = engineering(c.describe(name), raw)
    return value


FileArgument = typer.Argument(..., metavar="FILE", help="Operator data file (JSON); - is "
                              "standard output (export) or input (import).")
_TOOL_FIELDS = ("valid", "radius", "laenge", "name", "wear", "life_max")


def _write_text(path: str, text: str) -> None:
    if path == "-":
        sys.stdout.write(text)
        return
    try:
        Path(path).write_text(text, encoding="utf-8")
    except OSError as exc:
        fail(ClientValueError(f"{path}: cannot be written ({exc.strerror})"))


def _channel_entry(path: str, channel: int, section: str) -> ChannelData:
    """The entry of ``channel`` in the file, with ``section``; a clear error (exit 2,
    nothing written) otherwise."""
    try:
        text = sys.stdin.read() if path == "-" else Path(path).read_text(encoding="utf-8")
        data = loads(text)
    except (OSError, UnicodeDecodeError) as exc:
        fail(ClientValueError(f"{path}: cannot be read ({exc})"))
    except OperatorDataError as exc:
        fail(ClientValueError(f"{path}: {exc}"))
    entry = data.channel(channel)
    if entry is None or getattr(entry, section) is None:
        listed = [c.channel for c in data.channels if getattr(c, section) is not None]
        fail(ClientValueError(f"{path}: no {section} of channel {channel} (the file has "
                              f"them for channels {listed}); give --channel"))
    return entry


# ------------------------------------------------------------------ tools


def _tool_rows(c: Client, channel: int) -> tuple[int, dict[int, ToolRow]]:
    size: int = c.read(names.ch(channel).mc_tool_list_size_r)
    wanted = [f"ch{channel}.wz[{i}].{f}" for i in range(1, size + 1) for f in _TOOL_FIELDS]
    v = c.read_many(wanted)
    rows = {}
    for i in range(1, size + 1):
        p = f"ch{channel}.wz[{i}]."
        rows[i] = ToolRow(i, v[p + "valid"], in_mm(c, p + "radius", v[p + "radius"]),
                          in_mm(c, p + "laenge", v[p + "laenge"]), v[p + "name"],
                          in_mm(c, p + "wear", v[p + "wear"]), float(v[p + "life_max"]))
    return size, rows


def _empty(row: ToolRow) -> bool:
    return row == ToolRow(row.wz, False, 0.0, 0.0)


@tool_app.command("export")
def tool_export(ctx: typer.Context, file: str = FileArgument,
                channel: int = ChannelOption) -> None:
    """Write the channel's tool list (the rows that hold data) to FILE."""
    settings: Settings = ctx.obj
    _, rows = settings.call(lambda c: _tool_rows(c, channel), f"tool list of channel {channel}")
    kept = tuple(r for r in rows.values() if not _empty(r))
    _write_text(file, dumps(OperatorData((ChannelData(channel, tools=kept),))))
    if file != "-":
        emit(settings, {"channel": channel, "file": file, "rows": len(kept)},
             f"channel {channel}: {len(kept)} rows of the tool list written to {file}")


@tool_app.command("import")
def tool_import(ctx: typer.Context, file: str = FileArgument,
                channel: int = ChannelOption) -> None:
    """Make the channel's tool list the one of FILE (rows not in it are emptied)."""
    settings: Settings = ctx.obj
    entry = _channel_entry(file, channel, "tools")
    wanted = {r.wz: r for r in entry.tools or ()}

    def write(c: Client) -> int:
        size, rows = _tool_rows(c, channel)
        beyond = [i for i in wanted if i > size]
        if beyond:
            raise ClientValueError(f"{file}: wz[{beyond[0]}] is beyond the tool list of "
                                   f"channel {channel} (1..{size})")
        written = 0
        for i, now in rows.items():
            row = wanted.get(i, ToolRow(i, False, 0.0, 0.0))
            if row == now:
                continue
            prefix = f"ch{channel}.wz[{i}]"
            if not row.valid:  # emptied first: the old data is never a valid tool meanwhile
                c.write(f"{prefix}.valid", False)
            for name, mm in ((f"{prefix}.radius", row.radius_mm),
                             (f"{prefix}.laenge", row.length_mm),
                             (f"{prefix}.wear", row.wear_mm)):
                c.write(name, raw_value(c.describe(name), mm))
            c.write(f"{prefix}.name", row.name)
            c.write(f"{prefix}.life_max", row.life_max_s)
            if row.valid:
                c.write(f"{prefix}.valid", True)
            written += 1
        return written

    written = settings.call(write, f"tool list of channel {channel}")
    emit(settings, {"channel": channel, "file": file, "rows_written": written},
         f"channel {channel}: tool list from {file} ({written} rows written)")


# ------------------------------------------------------------------ zero offsets


def _groups(c: Client, channel: int) -> tuple[list[str], dict[int, OffsetGroup]]:
    count: int = c.read(names.ch(channel).mc_zero_offset_groups_r)
    axes = [a.upper() for a in c.axis_names(channel)]
    wanted = [f"ch{channel}.ax{a}.np_grp[{g}].v" for g in range(1, count)
              for a in range(1, len(axes) + 1)]
    v = c.read_many(wanted)
    groups = {}
    for g in range(1, count):
        values: dict[str, float] = {}
        for a, axis in enumerate(axes, start=1):
            name = f"ch{channel}.ax{a}.np_grp[{g}].v"
            values[axis] = in_mm(c, name, v[name])
        groups[g] = OffsetGroup(g, values)
    return axes, groups


@offsets_app.command("export")
def offsets_export(ctx: typer.Context, file: str = FileArgument,
                   channel: int = ChannelOption) -> None:
    """Write the channel's zero offset table (the groups not all zero) to FILE."""
    settings: Settings = ctx.obj
    _, groups = settings.call(lambda c: _groups(c, channel), f"zero offsets of channel {channel}")
    kept = tuple(g for g in groups.values() if any(g.offsets_mm.values()))
    _write_text(file, dumps(OperatorData((ChannelData(channel, zero_offsets=kept),))))
    if file != "-":
        emit(settings, {"channel": channel, "file": file, "groups": len(kept)},
             f"channel {channel}: {len(kept)} zero offset groups written to {file}")


@offsets_app.command("import")
def offsets_import(ctx: typer.Context, file: str = FileArgument,
                   channel: int = ChannelOption) -> None:
    """Make the channel's zero offset table the one of FILE (groups and axes not in it
    become 0)."""
    settings: Settings = ctx.obj
    entry = _channel_entry(file, channel, "zero_offsets")
    wanted = {g.np_grp: g for g in entry.zero_offsets or ()}

    def write(c: Client) -> int:
        axes, groups = _groups(c, channel)
        for g, group in wanted.items():
            if g not in groups:
                raise ClientValueError(f"{file}: np_grp[{g}] is beyond the zero offset "
                                       f"table of channel {channel} (1..{len(groups)})")
            unknown = [a for a in group.offsets_mm if a not in axes]
            if unknown:
                raise ClientValueError(f"{file}: np_grp[{g}] names axis {unknown[0]}; "
                                       f"channel {channel} has {', '.join(axes)}")
        written = 0
        for g, now in groups.items():
            want: dict[str, Any] = dict(wanted[g].offsets_mm) if g in wanted else {}
            for a, axis in enumerate(axes, start=1):
                mm = float(want.get(axis, 0.0))
                if mm != now.offsets_mm[axis]:
                    name = f"ch{channel}.ax{a}.np_grp[{g}].v"
                    c.write(name, raw_value(c.describe(name), mm))
                    written += 1
        return written

    written = settings.call(write, f"zero offsets of channel {channel}")
    emit(settings, {"channel": channel, "file": file, "values_written": written},
         f"channel {channel}: zero offsets from {file} ({written} values written)")
