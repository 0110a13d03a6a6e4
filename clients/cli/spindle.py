"""``cnc spindle``: show a channel's spindle and its technology units; set the override;
start and stop the spindle by a manual block (as an ISG HMI does: ``S.. M3`` / ``M5``).

The values are the channel's COM objects ``ch<c>.mc_spindle_*`` and
``ch<c>.mc_techno_<k>_*`` (docs/spindle-plc.md).
"""

from __future__ import annotations

from dataclasses import asdict
from typing import TYPE_CHECKING, Any

import typer

from .app import EXIT_USAGE, Settings, command, emit, err
from .machine import ChannelOption

if TYPE_CHECKING:  # a client is made by Settings, when a command connects
    from ..blocking import Client


@command()
def spindle(
    ctx: typer.Context,
    channel: int = ChannelOption,
    override: float = typer.Option(None, "--override", min=0.0, max=150.0,
                                   help="Set the spindle override (percent, 0..150)."),
    start: float = typer.Option(None, "--start", min=0.0, metavar="RPM",
                                help="Start the spindle at RPM by the manual block S<RPM> M3."),
    ccw: bool = typer.Option(False, "--ccw", help="With --start: M4 instead of M3."),
    stop: bool = typer.Option(False, "--stop", help="Stop the spindle by the manual block M5."),
) -> None:
    """Show the spindle of a channel (mode, programmed, commanded and actual speed,
    override) and the M/S/T functions output to the PLC; set the override, start or stop.

    Start and stop are manual blocks; the command returns when the block is done (with
    the embedded defaults M3/M4 wait for the speed, M5 for standstill).
    """
    settings: Settings = ctx.obj
    if start is not None and stop:
        err.print("error: --start and --stop exclude each other")
        raise typer.Exit(EXIT_USAGE)

    def act(c: Client) -> dict[str, Any]:
        if override is not None:
            c.set_spindle_override(override, channel)
        if start is not None:  # waits until the block is done (M3/M4: speed reached)
            c.start_spindle(start, ccw, channel, settings.timeout_s)
        elif stop:
            c.stop_spindle(channel, settings.timeout_s)
        return asdict(c.spindle(channel))

    s = settings.call(act, f"spindle of channel {channel}")
    lines = [
        (f"channel {channel} spindle: {s['mode']}  S{s['programmed_rpm']:g}  "
         f"commanded {s['commanded_rpm']:g} rpm  actual {s['actual_rpm']:g} rpm  "
         f"override {s['override_pct']:g} %  {'reached' if s['speed_reached'] else 'ramping'}"),
        *(f"  unit {k}: {u['type']}{u['number']} {u['sync']}"
          f"{' waits for the PLC' if u['pending'] else ''}" for k, u in enumerate(s["units"])),
    ]
    emit(settings, s, "\n".join(lines))
