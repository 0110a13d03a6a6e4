"""``cnc ads``: what an ADS client needs to know about the service's PLC symbols.

    cnc ads structure-def 'gpCh[0].spindle'    # pyads' structure_def of a struct, to copy

``structure-def`` prints Python: the structure_def of the struct symbol (and of the
structs inside it, first), padding members included, and the pyads calls that read and
write it by name (``clients/structure_def.py``, docs/ads.md); for an array of structs,
the element's, with pyads' ``array_size``. A symbol that is neither is one error line and
exit code 2; an unknown name the service's 0x710 and exit code 1.
"""

from __future__ import annotations

import typer

from .app import Settings, app, emit

ads_app = typer.Typer(
    no_args_is_help=True,
    help="What ADS clients need: the pyads structure_def of a PLC struct (structure-def).",
)
app.add_typer(ads_app, name="ads")


@ads_app.command("structure-def")
def structure_def(
    ctx: typer.Context,
    name: str = typer.Argument(..., metavar="NAME", help="A struct symbol on port 851, "
                               "e.g. 'gpCh[0].spindle' (quote the brackets for the shell)."),
) -> None:
    """Print pyads' structure_def of the PLC struct NAME (with its padding), ready to copy
    for read_structure_by_name and write_structure_by_name."""
    from ..structure_def import format_structure_def
    from ..structure_def import structure_def as build

    settings: Settings = ctx.obj
    found = settings.call(lambda c: build(c, name), f"structure-def {name}")
    text = format_structure_def(found)
    emit(settings, {"symbol": found.symbol, "type": found.type_name, "size": found.size,
                    "array_size": found.array_size, "structure_def": text}, text)

