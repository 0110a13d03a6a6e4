"""``cnc``: read, write, browse and watch CNC objects from the command line.

    cnc [--endpoint URL] [--json] [--timeout S] COMMAND ...

Exit codes: 0 done; 1 the service answered with an ADS error; 2 bad usage or a value
that does not parse; 3 the service did not answer (timeout, not reachable). Every error
is one line on stderr naming the ADS code in hex and its name.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import os
import sys
from collections.abc import Callable
from dataclasses import asdict
from typing import Annotated, Any, NoReturn, Optional, TypeVar

import typer
from rich.console import Console
from rich.table import Table

from cnc_objects.protocol.datatypes import DataType, parse_type, parse_value
from cnc_objects.protocol.errors import AdsReturnCode

from .client import DEFAULT_ENDPOINT, AsyncClient, Client, ObjectInfo
from .errors import AdsError, AdsTimeoutError

T = TypeVar("T")

EXIT_ADS_ERROR = 1
EXIT_USAGE = 2
EXIT_UNREACHABLE = 3

# The address options of read and write, declared once.
PortOption = Annotated[
    Optional[str], typer.Option("--port", help="ADS port (with --group, --offset, --type).")
]
GroupOption = Annotated[Optional[str], typer.Option("--group", help="Index group, decimal or 0x hex.")]
OffsetOption = Annotated[
    Optional[str], typer.Option("--offset", help="Index offset, decimal or 0x hex.")
]
TypeOption = Annotated[
    Optional[str], typer.Option("--type", help="Data type: UNS16, REAL64, STRING(84), ...")
]

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Read, write, browse and watch the objects of a cnc-objects service.",
)
out = Console(highlight=False, soft_wrap=True)
err = Console(stderr=True, highlight=False, soft_wrap=True)


class Settings:
    """Global options, shared by every command."""

    def __init__(self, endpoint: str, as_json: bool, timeout_s: float) -> None:
        self.endpoint = endpoint
        self.as_json = as_json
        self.timeout_s = timeout_s

    def client(self) -> Client:
        """A blocking client for one command."""
        return Client(self.endpoint, timeout_s=self.timeout_s)

    def call(self, operation: Callable[[Client], T]) -> T:
        """``operation`` on a client of its own; an ADS error ends the command."""
        try:
            with self.client() as c:
                return operation(c)
        except AdsError as exc:
            _fail(exc)


def _fail(exc: Exception) -> NoReturn:
    if isinstance(exc, AdsTimeoutError):
        err.print(f"error: {exc}")
        raise typer.Exit(EXIT_UNREACHABLE)
    if isinstance(exc, AdsError):
        err.print(f"error: {exc}")
        raise typer.Exit(EXIT_USAGE if exc.code == AdsReturnCode.CLIENT_INVALIDPARM else EXIT_ADS_ERROR)
    err.print(f"error: {exc}")
    raise typer.Exit(EXIT_USAGE)


def _number(text: str, what: str) -> int:
    try:
        return int(text, 0)
    except ValueError:
        err.print(f"error: {what} {text!r} is not a number (decimal or 0x hex)")
        raise typer.Exit(EXIT_USAGE) from None


def _emit(settings: Settings, record: dict[str, Any], human: str) -> None:
    if settings.as_json:
        out.print(json.dumps(record, default=str), markup=False)
    else:
        out.print(human, markup=False)


def _address(port: str | None, group: str | None, offset: str | None, dtype: str | None):
    given = [x is not None for x in (port, group, offset, dtype)]
    if not any(given):
        return None
    if not all(given):
        err.print("error: an address needs all of --port, --group, --offset and --type")
        raise typer.Exit(EXIT_USAGE)
    try:
        parsed_type = parse_type(dtype)  # type: ignore[arg-type]
    except ValueError as exc:
        err.print(f"error: {exc}")
        raise typer.Exit(EXIT_USAGE) from None
    return (
        _number(port, "port"),  # type: ignore[arg-type]
        _number(group, "group"),  # type: ignore[arg-type]
        _number(offset, "offset"),  # type: ignore[arg-type]
        parsed_type,
    )


def _parse(dtype: DataType, text: str) -> Any:
    try:
        return parse_value(dtype, text)
    except ValueError as exc:
        err.print(f"error: ADS {AdsReturnCode.DEVICE_INVALIDDATA:#x} INVALIDDATA: {exc}")
        raise typer.Exit(EXIT_USAGE) from None


@app.callback()
def main_options(
    ctx: typer.Context,
    endpoint: str = typer.Option(
        os.environ.get("CNC_ENDPOINT", DEFAULT_ENDPOINT), "--endpoint", "-e",
        help="Service endpoint (default: $CNC_ENDPOINT, else tcp://127.0.0.1:5555).",
    ),
    as_json: bool = typer.Option(False, "--json", help="One JSON object per line."),
    timeout_s: float = typer.Option(5.0, "--timeout", min=0.01, help="Seconds to wait for a reply."),
) -> None:
    """Global options."""
    ctx.obj = Settings(endpoint, as_json, timeout_s)


@app.command()
def info(ctx: typer.Context) -> None:
    """Device name, version and ADS state of the service."""
    settings: Settings = ctx.obj
    device = settings.call(lambda c: c.info())
    record = {
        "name": device.name,
        "version": device.version,
        "ads_state": device.ads_state.name,
        "device_state": device.device_state,
        "endpoint": settings.endpoint,
    }
    _emit(settings, record, f"{device.name} {device.version} at {settings.endpoint}: "
          f"ADS state {device.ads_state.name}")


@app.command()
def browse(
    ctx: typer.Context, pattern: str = typer.Argument("*", help="Glob over object names.")
) -> None:
    """List the objects whose names match PATTERN."""
    settings: Settings = ctx.obj
    found = settings.call(lambda c: c.browse(pattern))
    if settings.as_json:
        for o in found:
            _emit(settings, asdict(o), "")
        return
    table = Table("name", "port", "group", "offset", "type", "access", "unit", "description")
    for o in found:
        table.add_row(o.name, str(o.port), f"0x{o.group:x}", f"0x{o.offset:x}", o.type,
                      o.access, o.unit, o.description)
    out.print(table)
    out.print(f"{len(found)} objects")


@app.command()
def read(
    ctx: typer.Context,
    names: list[str] = typer.Argument(None, help="Object names."),
    port: PortOption = None,
    group: GroupOption = None,
    offset: OffsetOption = None,
    dtype: TypeOption = None,
) -> None:
    """Read objects by name, or one value by address."""
    settings: Settings = ctx.obj
    address = _address(port, group, offset, dtype)
    if (address is None) == (not names):
        err.print("error: give object names or an address (--port --group --offset --type)")
        raise typer.Exit(EXIT_USAGE)
    try:
        with settings.client() as c:
            if address is not None:
                value = c.read_address(*address)
                p, g, o, t = address
                _emit(settings, {"port": p, "group": g, "offset": o, "type": t.name, "value": value},
                      f"{p}:0x{g:x}:0x{o:x} = {value}")
                return
            values = c.read_many(names) if len(names) > 1 else {names[0]: c.read(names[0])}
            infos = {n: c.describe(n) for n in values}
    except AdsError as exc:
        _fail(exc)
    for name, value in values.items():
        unit = infos[name].unit
        suffix = f" {unit}" if unit and unit != "-" else ""
        _emit(settings, {"name": name, "value": value}, f"{name} = {value}{suffix}")


@app.command()
def write(
    ctx: typer.Context,
    args: list[str] = typer.Argument(..., help="NAME VALUE, or VALUE with an address."),
    port: PortOption = None,
    group: GroupOption = None,
    offset: OffsetOption = None,
    dtype: TypeOption = None,
) -> None:
    """Write an object by name (NAME VALUE) or a value by address (VALUE)."""
    settings: Settings = ctx.obj
    address = _address(port, group, offset, dtype)
    if len(args) != (1 if address is not None else 2):
        err.print("error: write takes NAME VALUE, or VALUE with --port --group --offset --type")
        raise typer.Exit(EXIT_USAGE)
    try:
        with settings.client() as c:
            if address is not None:
                p, g, o, t = address
                value = _parse(t, args[0])
                c.write_address(p, g, o, t, value)
                _emit(settings, {"port": p, "group": g, "offset": o, "value": value, "ok": True},
                      f"{p}:0x{g:x}:0x{o:x} := {value}")
                return
            name, text = args
            info_: ObjectInfo = c.describe(name)
            value = _parse(info_.dtype, text)
            c.write(name, value)
    except AdsError as exc:
        _fail(exc)
    _emit(settings, {"name": info_.name, "value": value, "ok": True}, f"{info_.name} := {value}")


@app.command()
def watch(
    ctx: typer.Context,
    names: list[str] = typer.Argument(..., help="Object names."),
    count: int = typer.Option(0, min=0, help="Stop after COUNT samples of each object (0: never)."),
    cycle_ms: int = typer.Option(None, "--cycle-ms", min=0, help="Sampling cycle in kernel ms."),
    cyclic: bool = typer.Option(False, help="Send every cycle, not only on change."),
) -> None:
    """Print samples of objects as the service sends them (until Ctrl-C or COUNT)."""
    settings: Settings = ctx.obj

    async def one(c: AsyncClient, name: str) -> None:
        seen = 0
        samples = c.subscribe(name, on_change=not cyclic, cycle_ms=cycle_ms)
        async with contextlib.aclosing(samples):  # deletes the notification on the way out
            async for s in samples:
                _emit(
                    settings,
                    {"name": s.name, "value": s.value, "ts": s.timestamp.isoformat(),
                     "seq": s.sequence},
                    f"{s.timestamp.isoformat(timespec='milliseconds')} #{s.sequence} "
                    f"{s.name} = {s.value}",
                )
                seen += 1
                if count and seen >= count:
                    return

    async def run() -> None:
        async with AsyncClient(settings.endpoint, timeout_s=settings.timeout_s) as c:
            for name in names:  # fail on a bad name before printing anything
                await c.describe(name)
            await asyncio.gather(*(one(c, name) for name in names))

    try:
        asyncio.run(run())
    except KeyboardInterrupt:
        raise typer.Exit(0) from None
    except AdsError as exc:
        _fail(exc)


def main() -> None:
    """Entry point of ``cnc``."""
    try:
        app()
    except KeyboardInterrupt:
        sys.exit(130)


# The machine-operating commands register themselves on ``app``.
from . import cli_machine, cli_plot  # noqa: E402,F401
