"""``cnc spindle``: show a channel's spindle and its technology units; set the override;
start and stop the spindle by a manual block (as an ISG HMI does: ``S.. M3`` / ``M5``).

The values are the channel's COM objects ``ch<c>.mc_spindle_*`` and
``ch<c>.mc_techno_<k>_*`` (docs/spindle-plc.md).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import typer

from .cli_app import EXIT_USAGE, Settings, command, emit, err
from .cli_machine import ChannelOption
from .units import engineering, raw_value

if TYPE_CHECKING:  # a client is made by Settings, when a command connects
    from .blocking import Client
MODE_NAMES = {1: "M5", 2: "M3", 4: "M4", 8: "M19"}
SYNC_NAMES = {0: "-", 1: "MOS", 2: "MVS_SVS", 4: "MVS_SNS", 8: "MNS_SNS"}
TYPE_NAMES = {1: "M", 2: "H", 3: "S", 4: "T"}
TECHNO_UNITS = 16


def _engineering(c: Client, name: str) -> Any:
    """The value of ``name`` in engineering units (rpm, %)."""
    return engineering(c.describe(name), c.read(name))


def read_spindle(c: Client, channel: int) -> dict[str, Any]:
    """The spindle's values and the listed technology units of ``channel``."""
    p = f"ch{channel}.mc_spindle_"
    units = []
    for k in range(TECHNO_UNITS):
        q = f"ch{channel}.mc_techno_{k}_"
        kind = c.read(q + "typ")
        if not kind:
            break
        units.append({"type": TYPE_NAMES.get(kind, str(kind)), "number": c.read(q + "nr"),
                      "sync": SYNC_NAMES.get(c.read(q + "synch"), "?"),
                      "pending": bool(c.read(q + "state"))})
    return {
        "channel": channel,
        "mode": MODE_NAMES.get(c.read(p + "mode_r"), "?"),
        # 0.001 deg/s -> rpm, 0.1 % -> %: by the scale the service gives for each object
        "programmed_rpm": _engineering(c, p + "prog_rev_r"),
        "commanded_rpm": _engineering(c, p + "cmd_rev_r"),
        "actual_rpm": _engineering(c, p + "active_rev_r"),
        "override_pct": _engineering(c, p + "override_w"),
        "speed_reached": bool(c.read(p + "speed_reached_r")),
        "units": units,
    }


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
            target = f"ch{channel}.mc_spindle_override_w"  # 0.1 %; the scale says
            c.write(target, raw_value(c.describe(target), override))
        block = "M5" if stop else None
        if start is not None:
            block = f"S{start:g} {'M4' if ccw else 'M3'}"
        if block is not None:  # waits until the block is done (M3/M4: speed reached)
            c.wait_mdi(c.mdi(block, channel), channel, settings.timeout_s)
        return read_spindle(c, channel)

    s = settings.call(act, f"spindle of channel {channel}")
    lines = [
        (f"channel {channel} spindle: {s['mode']}  S{s['programmed_rpm']:g}  "
         f"commanded {s['commanded_rpm']:g} rpm  actual {s['actual_rpm']:g} rpm  "
         f"override {s['override_pct']:g} %  {'reached' if s['speed_reached'] else 'ramping'}"),
        *(f"  unit {k}: {u['type']}{u['number']} {u['sync']}"
          f"{' waits for the PLC' if u['pending'] else ''}" for k, u in enumerate(s["units"])),
    ]
    emit(settings, s, "\n".join(lines))
