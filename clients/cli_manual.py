"""``cnc`` commands of manual mode: jog an axis, turn the handwheel, home axes.

    cnc jog AXIS +|- [--increment MM] [--channel N] [--rapid] [--no-wait] [--wait-timeout S]
    cnc jog AXIS +|- --continuous        (held, renewed, until the axis stands or Ctrl-C)
    cnc jog AXIS --stop
    cnc jog AXIS +|- --handwheel PULSES  (the handwheel counter moves by PULSES)
    cnc home AXIS... [--channel N] [--wait-timeout S]

Each command selects the channel mode MANUAL when the channel is in another mode and
idle, then writes the axis's manual-mode objects (docs/manual.md) as an HMI would. AXIS
is the axis name in the channel (``X``) or its index from 1. Without ``--no-wait`` the
command waits until the axis stands and prints where; a stop at a software limit is
told on stderr (``warning: ...``, exit 0). A refusal (channel in ERROR or HOLD, axis
homing, value out of range) exits 1 with the kernel's sentence; ``--wait-timeout`` exits 5.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

import typer

from .cli_app import EXIT_USAGE, Settings, command, emit, err, fail, say_error
from .errors import AdsError, ClientValueError
from .units import engineering, raw_value

if TYPE_CHECKING:  # a client is made by Settings, when a command connects
    from .blocking import Client

EXIT_WAIT_TIMEOUT = 5
_MANUAL = 4  # ChannelMode.MANUAL
_HANDWHEEL, _CONTINUOUS, _INCREMENTAL = 1, 2, 3  # ManualOperationMode
_POLL_S = 0.02
_MAX_AXES = 32
AxesArgument = typer.Argument(..., metavar="AXIS...", help="Axis names (X Y Z) or indices, homed together.")


def _axis_index(c: Client, channel: int, axis: str) -> int:
    """The index (from 1) of ``axis``, given by name or by index."""
    names: list[str] = []
    for k in range(1, _MAX_AXES + 1):
        try:
            names.append(c.read(f"ch{channel}.ax{k}.axis_name"))
        except (AdsError, ClientValueError, KeyError):
            break
    if axis.isdigit() and 1 <= int(axis) <= len(names):
        return int(axis)
    for k, name in enumerate(names, start=1):
        if name.upper() == axis.upper():
            return k
    say_error(f"channel {channel} has no axis {axis!r} (axes: {', '.join(names)})")
    raise typer.Exit(EXIT_USAGE)


def _manual_mode(c: Client, channel: int) -> None:
    """Select MANUAL unless the channel is in it (the kernel refuses while it works)."""
    if c.read(f"ch{channel}.mc_active_mode_r") != _MANUAL:
        c.write(f"ch{channel}.mc_command_mode_w", _MANUAL)


def _wait_standstill(c: Client, prefix: str, timeout_s: float | None,
                     also: str | None = None) -> None:
    """Poll until the axis's manual motion is over (and ``also`` is FALSE)."""
    deadline = None if timeout_s is None else time.monotonic() + timeout_s
    names = [f"{prefix}.manual_moving_r"] + ([also] if also else [])
    while any(c.read_many(names).values()):
        if deadline is not None and time.monotonic() > deadline:
            say_error(f"{prefix} still moves after {timeout_s:g} s")
            raise typer.Exit(EXIT_WAIT_TIMEOUT)
        time.sleep(_POLL_S)


def _hold(c: Client, prefix: str, key: str, timeout_s: float | None) -> None:
    """Press ``key`` and hold it, renewed every ``RENEW_S`` (the service's dead-man
    releases a key that is not: docs/manual.md), until the axis stands (its software
    limit), Ctrl-C or ``timeout_s``; then release it."""
    from .jog_hold import RENEW_S  # here: ``cnc --help`` imports no asyncio

    deadline = None if timeout_s is None else time.monotonic() + timeout_s
    c.write(key, True)
    try:
        renew_at_s = time.monotonic() + RENEW_S
        while c.read(f"{prefix}.manual_moving_r"):
            now_s = time.monotonic()
            if deadline is not None and now_s > deadline:
                return  # released below: the timeout ends the jog
            if now_s >= renew_at_s:
                c.write(key, True)
                renew_at_s = now_s + RENEW_S
            time.sleep(_POLL_S)
    finally:
        c.write(key, False)


def _report(settings: Settings, c: Client, channel: int, axis: int, name: str) -> None:
    prefix = f"ch{channel}.ax{axis}"
    values = c.read_many([f"{prefix}.command_position_acs", f"{prefix}.manual_limit_warning_r",
                          f"{prefix}.manual_moving_r", f"{prefix}.homing_referenced_r"])
    position = f"{prefix}.command_position_acs"
    position_mm = engineering(c.describe(position), values[position])  # 0.1 um -> mm
    at_limit = values[f"{prefix}.manual_limit_warning_r"]
    if at_limit:
        err.print(f"warning: axis {name} stopped at its software limit", markup=False,
                  emoji=False)
    record: dict[str, Any] = {
        "channel": channel, "axis": name, "position_mm": position_mm,
        "moving": values[f"{prefix}.manual_moving_r"], "limit_warning": at_limit,
        "referenced": values[f"{prefix}.homing_referenced_r"],
    }
    state = "moving" if record["moving"] else "stands"
    emit(settings, record, f"channel {channel}: axis {name} {state} at {position_mm:.4f} mm")


@command()
def jog(
    ctx: typer.Context,
    axis: str = typer.Argument(..., metavar="AXIS", help="Axis name in the channel (X) or index from 1."),
    direction: str = typer.Argument(None, metavar="[+|-]", help="+ or - (not with --stop)."),
    increment_mm: float = typer.Option(
        None, "--increment", help="Jog by increments: this distance (mm, 0.0001..10). "
        "The default when no other mode is given: 1 mm."),
    continuous: bool = typer.Option(False, "--continuous",
                                    help="Continuous jog: hold the key (renewed) until the "
                                    "axis stands at its limit, Ctrl-C or --wait-timeout."),
    stop: bool = typer.Option(False, "--stop", help="Release the axis's jog keys."),
    handwheel: int = typer.Option(None, "--handwheel",
                                  help="Handwheel mode: turn the counter by PULSES."),
    rapid: bool = typer.Option(False, "--rapid", help="Press the rapid key (rapid jog speed)."),
    channel: int = typer.Option(1, "--channel", "-c", min=1, metavar="N", help="Channel id (default 1)."),
    no_wait: bool = typer.Option(False, "--no-wait", help="Do not wait for standstill."),
    timeout_s: float = typer.Option(None, "--wait-timeout", min=0.0, metavar="S",
                                    help="Give up waiting after S seconds (exit 5)."),
) -> None:
    """Jog an axis in manual mode: by an increment (default 1 mm), continuously, or by the
    handwheel."""
    settings: Settings = ctx.obj
    chosen = sum((increment_mm is not None, continuous, stop, handwheel is not None))
    if chosen > 1:
        say_error("choose one of --increment, --continuous, --stop, --handwheel")
        raise typer.Exit(EXIT_USAGE)
    if not stop and direction not in ("+", "-"):
        say_error("give the direction: + or -")
        raise typer.Exit(EXIT_USAGE)
    try:
        with settings.session(f"jog of {axis} in channel {channel}") as c:
            k = _axis_index(c, channel, axis)
            name = c.read(f"ch{channel}.ax{k}.axis_name")
            prefix = f"ch{channel}.ax{k}"
            key = f"{prefix}.manual_jog_{'plus' if direction == '+' else 'minus'}_w"
            if stop:
                c.write(f"{prefix}.manual_jog_plus_w", False)
                c.write(f"{prefix}.manual_jog_minus_w", False)
            else:
                _manual_mode(c, channel)
                c.write(f"{prefix}.manual_rapid_w", rapid)
                if handwheel is not None:
                    c.write(f"{prefix}.manual_operation_mode_w", _HANDWHEEL)
                    counter = c.read(f"{prefix}.manual_handwheel_counter_w")
                    sign = 1 if direction == "+" else -1
                    wrapped = (counter + sign * handwheel + 2**31) % 2**32 - 2**31
                    c.write(f"{prefix}.manual_handwheel_counter_w", wrapped)
                elif continuous:
                    c.write(f"{prefix}.manual_operation_mode_w", _CONTINUOUS)
                    _hold(c, prefix, key, timeout_s)
                    no_wait = True  # held until it stood
                else:
                    c.write(f"{prefix}.manual_operation_mode_w", _INCREMENTAL)
                    increment = f"{prefix}.manual_increment_w"  # 0.1 um; the scale says
                    c.write(increment, raw_value(c.describe(increment),
                                                 1.0 if increment_mm is None else increment_mm))
                    c.write(key, True)
                    c.write(key, False)
            if not no_wait:
                _wait_standstill(c, prefix, timeout_s)
            _report(settings, c, channel, k, name)
    except (AdsError, ClientValueError) as exc:
        fail(exc)


@command()
def home(
    ctx: typer.Context,
    axes: list[str] = AxesArgument,
    channel: int = typer.Option(1, "--channel", "-c", min=1, metavar="N", help="Channel id (default 1)."),
    timeout_s: float = typer.Option(None, "--wait-timeout", min=0.0, metavar="S",
                                    help="Give up waiting after S seconds (exit 5)."),
) -> None:
    """Home axes in manual mode (to their reference position P-AXIS-00152) and wait until
    they are referenced."""
    settings: Settings = ctx.obj
    try:
        with settings.session(f"homing in channel {channel}") as c:
            indices = [_axis_index(c, channel, a) for a in axes]
            _manual_mode(c, channel)
            for k in indices:
                c.write(f"ch{channel}.ax{k}.homing_start_w", True)
            for k in indices:
                prefix = f"ch{channel}.ax{k}"
                _wait_standstill(c, prefix, timeout_s, also=f"{prefix}.homing_active_r")
            for k in indices:
                _report(settings, c, channel, k, c.read(f"ch{channel}.ax{k}.axis_name"))
    except (AdsError, ClientValueError) as exc:
        fail(exc)
