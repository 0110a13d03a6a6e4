"""``cnc`` commands on objects: info, browse, read, write, watch.

    cnc info                             cnc browse [PATTERN]
    cnc read NAME... [--raw] | --port P --group G --offset O --type T
    cnc write NAME VALUE [--raw] | VALUE --port P --group G --offset O --type T
    cnc watch NAME... [--raw] [--count N] [--wait-timeout S] [--cyclic] [--cycle-ms MS]

A value is printed in engineering units, as the service's scale of the object says
(``ch1.mc_active_feed_override_r = 50.0 %``, ``ch1.ax1.command_position_acs = 12.5000
mm``), an enumeration value with its name (``ch1.mc_active_state_r = 3 (READY)``);
``--raw`` prints the object's own value and unit (``500 (0.1 %)``). ``--json`` gives
``"value"`` and ``"unit"`` in engineering units and ``"raw"``, ``"raw_unit"`` beside them
(``"value_name"`` for a named value). ``write`` takes the value in the same engineering
unit (``cnc write ch1.mc_command_feed_override_w 75`` is 75 %), ``--raw`` the object's
own. Negative values need no ``--``: ``cnc write ch1.x -1``. A misspelt name fails with
ADS 0x710 and the nearest names (``did you mean ...?``).
"""

from __future__ import annotations

import contextlib
from dataclasses import asdict
from typing import TYPE_CHECKING, Annotated, Any

import typer

from cnc_objects.protocol.datatypes import DataType, parse_type, parse_value

from ..errors import AdsError, ClientValueError, NoReplyError
from ..object_info import ObjectInfo
from ..units import parse_engineering, record, show
from .app import EXIT_USAGE, Settings, command, emit, fail, out, say_error

if TYPE_CHECKING:  # a client is made by Settings, when a command connects
    from ..blocking import Client
    from ..client import AsyncClient

EXIT_WATCH_TIMEOUT = 5  # watch --count N --wait-timeout S: a name got fewer than N samples

# The address options of read and write, declared once.
PortOption = Annotated[
    str | None, typer.Option("--port", help="ADS port (with --group, --offset, --type).")
]
GroupOption = Annotated[str | None, typer.Option("--group", help="Index group, decimal or 0x hex.")]
OffsetOption = Annotated[
    str | None, typer.Option("--offset", help="Index offset, decimal or 0x hex.")
]
TypeOption = Annotated[
    str | None, typer.Option("--type", help="Data type: UNS16, REAL64, STRING(84), ...")
]
_BROWSE_COLUMNS = ("name", "port", "group", "offset", "type", "access", "unit", "description")
RawOption = Annotated[bool, typer.Option(
    "--raw", help="The object's own value and unit (0.1 um, 0.1 %), not mm, mm/min, %.")]


def _number(text: str, what: str) -> int:
    try:
        return int(text, 0)
    except ValueError:
        say_error(f"{what} {text!r} is not a number (decimal or 0x hex)")
        raise typer.Exit(EXIT_USAGE) from None


def _address(
    port: str | None, group: str | None, offset: str | None, dtype: str | None
) -> tuple[int, int, int, DataType] | None:
    given = [x is not None for x in (port, group, offset, dtype)]
    if not any(given):
        return None
    if not all(given):
        say_error("an address needs all of --port, --group, --offset and --type")
        raise typer.Exit(EXIT_USAGE)
    try:
        parsed_type = parse_type(dtype)  # type: ignore[arg-type]
    except ValueError as exc:
        say_error(str(exc))
        raise typer.Exit(EXIT_USAGE) from None
    return (
        _number(port, "port"),  # type: ignore[arg-type]
        _number(group, "group"),  # type: ignore[arg-type]
        _number(offset, "offset"),  # type: ignore[arg-type]
        parsed_type,
    )


def _parse(dtype: DataType, text: str, what: str) -> Any:
    """The value typed for ``what``; text that does not parse exits 2 (nothing is sent)."""
    try:
        return parse_value(dtype, text)
    except ValueError as exc:
        say_error(f"{what}: {exc}")
        raise typer.Exit(EXIT_USAGE) from None


@command()
def info(ctx: typer.Context) -> None:
    """Device name, version and ADS state of the service."""
    settings: Settings = ctx.obj
    device = settings.call(lambda c: c.info(), "device info")
    record = {
        "name": device.name,
        "version": device.version,
        "ads_state": device.ads_state.name,
        "device_state": device.device_state,
        "endpoint": settings.endpoint,
    }
    emit(settings, record, f"{device.name} {device.version} at {settings.endpoint}: "
         f"ADS state {device.ads_state.name}")


@command()
def browse(
    ctx: typer.Context,
    pattern: str = typer.Argument("*", metavar="[PATTERN]", help="Glob over object names."),
) -> None:
    """List the objects whose names match PATTERN.

    On a terminal: aligned columns, description last, nothing cut (a long line wraps).
    Piped: a header line, then one tab-separated line per object, for grep, cut and awk.
    """
    settings: Settings = ctx.obj
    found = settings.call(lambda c: c.browse(pattern), f"BROWSE {pattern}")
    if settings.as_json:
        for o in found:
            emit(settings, asdict(o), "")
        return
    rows = [tuple(" ".join(field.split()) for field in (  # one line per object
        o.name, str(o.port), f"0x{o.group:x}", f"0x{o.offset:x}", o.type, o.access, o.unit,
        o.description)) for o in found]
    if not out.is_terminal:  # for grep, cut, awk: full rows, one per line
        for row in (_BROWSE_COLUMNS, *rows):
            print("\t".join(row))  # not through rich, which would expand the tabs
        return
    # Aligned columns, description last: nothing is cut at any terminal width (a long
    # line wraps in the terminal), unlike a table that fits its cells to the width.
    widths = [max(len(r[k]) for r in (_BROWSE_COLUMNS, *rows)) for k in range(7)]
    for k, row in enumerate((_BROWSE_COLUMNS, *rows)):
        line = "  ".join(field.ljust(width) for field, width in zip(row, widths)) + "  " + row[7]
        out.print(line, markup=False, emoji=False, style="bold" if k == 0 else None)
    out.print(f"{len(found)} objects")


@command()
def read(
    ctx: typer.Context,
    names: list[str] = typer.Argument(None, metavar="[NAME]...", help="Object names."),
    port: PortOption = None,
    group: GroupOption = None,
    offset: OffsetOption = None,
    dtype: TypeOption = None,
    raw: RawOption = False,
) -> None:
    """Read objects by name (globs: ch1.mc_*_w), or one value by address.

    A value is shown in engineering units (12.5000 mm, 1200.000 mm/min, 50.0 %) or with
    its name: 3 (READY); --raw shows the object's own value and unit: 500 (0.1 %). With
    --json "value" and "unit" are in engineering units, "raw" and "raw_unit" the object's
    own, "value_name" the name of a named value.
    """
    settings: Settings = ctx.obj
    address = _address(port, group, offset, dtype)
    if (address is None) == (not names):
        say_error("give object names or an address (--port --group --offset --type)")
        raise typer.Exit(EXIT_USAGE)
    try:
        with settings.client() as c:
            if address is not None:
                value = c.read_address(*address)
                p, g, o, t = address
                emit(settings, {"port": p, "group": g, "offset": o, "type": t.name, "value": value},
                     f"{p}:0x{g:x}:0x{o:x} = {value}")
                return
            alone = _read_alone(c, names[0]) if len(names) == 1 else None
            if alone is not None:
                values, infos = {names[0]: alone[1]}, {names[0]: alone[0]}
            else:
                names = _expanded(c, names)
                values = c.read_many(names) if len(names) > 1 else {names[0]: c.read(names[0])}
                infos = {n: c.describe(n) for n in values}
    except (AdsError, ClientValueError) as exc:
        fail(exc)
    for name, value in values.items():
        emit(settings, record(infos[name], value, raw), f"{name} = {show(infos[name], value, raw)}")


def _read_alone(client: Client, name: str) -> tuple[ObjectInfo, Any] | None:
    """The description and value of the one object ``name`` (no glob) from a browse of
    that name alone and a read by address: two small round trips, where a read by name
    first loads the whole catalog (some 2 700 descriptions, a third of a ``cnc read``'s
    time). None when the browse does not find exactly that name (a glob, an unknown name,
    another case): the caller's read by name then says what it says (did you mean ...)."""
    if "*" in name or "?" in name:
        return None
    try:
        found = [info for info in client.browse(name) if info.name == name]
        if len(found) != 1:
            return None
        info = found[0]
        return info, client.read_address(info.port, info.group, info.offset, info.dtype)
    except NoReplyError as exc:  # the user asked for a READ, not for a BROWSE
        raise exc.asking(f"READ {name}") from None


def _expanded(client: Any, names: list[str]) -> list[str]:
    """``names`` with each glob (``ch1.mc_*_w``; a bracketed number is an index, not a
    class) replaced by the names it matches, in catalog order; a glob that matches
    nothing stays, so that its read says the name is unknown."""
    out: list[str] = []
    for name in names:
        if "*" in name or "?" in name:
            out += [info.name for info in client.browse(name)] or [name]
        else:
            out.append(name)
    return out


# A negative value ("-1") is a value, not an unknown option.
@command(context_settings={"ignore_unknown_options": True})
def write(
    ctx: typer.Context,
    args: list[str] = typer.Argument(
        ..., metavar="[NAME] VALUE", help="NAME VALUE, or VALUE with an address. "
        "Negative values as they are: write ch1.x -1."),
    port: PortOption = None,
    group: GroupOption = None,
    offset: OffsetOption = None,
    dtype: TypeOption = None,
    raw: Annotated[bool, typer.Option(
        "--raw", help="VALUE is the object's own (0.1 um, 0.1 %), not mm, mm/min, %.")] = False,
) -> None:
    """Write an object by name (NAME VALUE) or a value by address (VALUE).

    An object with an engineering unit takes VALUE in it, as read shows it: mm for
    positions, mm/min for speeds, % for overrides (write ch1.mc_command_feed_override_w
    75); --raw takes the object's own value (750, in 0.1 %). Integers in decimal or 0x
    hex, negative ones as they are (write ch1.x -1); booleans 0/1/true/false. A value its
    type cannot hold is refused before anything is sent (exit 2).
    """
    settings: Settings = ctx.obj
    address = _address(port, group, offset, dtype)
    if len(args) != (1 if address is not None else 2):
        say_error("write takes NAME VALUE, or VALUE with --port --group --offset --type")
        raise typer.Exit(EXIT_USAGE)
    try:
        with settings.client() as c:
            if address is not None:
                p, g, o, t = address
                value = _parse(t, args[0], f"{p}:0x{g:x}:0x{o:x}")
                c.write_address(p, g, o, t, value)
                emit(settings, {"port": p, "group": g, "offset": o, "value": value, "ok": True},
                     f"{p}:0x{g:x}:0x{o:x} := {value}")
                return
            name, text = args
            try:
                info_: ObjectInfo = c.describe(name)
            except NoReplyError as exc:  # describing is a BROWSE; the user asked to write
                raise exc.asking(f"WRITE {name}") from None
            if raw or info_.scale is None:
                value = _parse(info_.dtype, text, info_.name)
            else:
                value = parse_engineering(info_, text)
            c.write(name, value)
    except (AdsError, ClientValueError) as exc:
        fail(exc)
    emit(settings, {**record(info_, value, raw), "ok": True},
         f"{info_.name} := {show(info_, value, raw)}")


@command()
def watch(
    ctx: typer.Context,
    names: list[str] = typer.Argument(..., metavar="NAME...", help="Object names."),
    count: int = typer.Option(
        0, min=0, help="Stop after COUNT samples of each object (0: never). The first "
        "sample is the current value; on change, the next ones come only when it changes."),
    timeout_s: float = typer.Option(
        None, "--wait-timeout", min=0.0, metavar="S", help="Stop after S seconds; with --count, exit 5 when "
        "an object got fewer than COUNT samples by then."),
    cycle_ms: int = typer.Option(None, "--cycle-ms", min=0, help="Sampling cycle in kernel ms "
                                 "(default 10 on change, 0: every cycle; 100 with --cyclic)."),
    cyclic: bool = typer.Option(False, help="Send every cycle, not only on change."),
    raw: RawOption = False,
) -> None:
    """Print samples of objects as the service sends them (until Ctrl-C, COUNT, --wait-timeout).

    Each object's first sample is its current value, sent at subscription. On change
    (the default) the next sample comes only when the value changes, so --count 2 of a
    value that stays waits for a change: bound the wait with --wait-timeout (exit 5 when
    COUNT was not reached), or use --cyclic for a sample every cycle.
    """
    import asyncio  # here: the commands that need no event loop start without it

    settings: Settings = ctx.obj
    seen = dict.fromkeys(names, 0)

    async def one(c: AsyncClient, name: str, info_: ObjectInfo) -> None:
        samples = c.subscribe(name, on_change=not cyclic, cycle_ms=cycle_ms)
        async with contextlib.aclosing(samples):  # deletes the notification on the way out
            async for s in samples:
                emit(
                    settings,
                    {**record(info_, s.value, raw), "ts": s.timestamp.isoformat(),
                     "seq": s.sequence},
                    f"{s.timestamp.isoformat(timespec='milliseconds')} #{s.sequence} "
                    f"{s.name} = {show(info_, s.value, raw)}",
                )
                seen[name] += 1
                if count and seen[name] >= count:
                    return

    async def run() -> bool:
        """True when every object got its samples (or no COUNT), False at --wait-timeout."""
        async with settings.async_client() as c:
            infos = {}
            for name in names:  # fail on a bad name before printing anything
                try:
                    infos[name] = await c.describe(name)
                except NoReplyError as exc:
                    raise exc.asking(f"SUBSCRIBE {name}") from None
            timer = asyncio.timeout(timeout_s)
            try:
                async with timer:
                    await asyncio.gather(*(one(c, name, infos[name]) for name in names))
            except TimeoutError:
                if not timer.expired():
                    raise  # a request without reply, not --wait-timeout
                return not count or all(n >= count for n in seen.values())
        return True

    try:
        complete = asyncio.run(run())
    except KeyboardInterrupt:
        raise typer.Exit(0) from None
    except (AdsError, ClientValueError) as exc:
        fail(exc)
    if not complete:
        short = ", ".join(f"{n} {seen[n]} of {count}" for n in names if seen[n] < count)
        say_error(f"watch ended after {timeout_s:g} s with fewer samples than --count: "
                  f"{short} (on change, a sample comes only when the value changes)")
        raise typer.Exit(EXIT_WATCH_TIMEOUT)
