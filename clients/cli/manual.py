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

from typing import TYPE_CHECKING, Any

import typer

from ..errors import AdsError, AdsTimeoutError, ClientValueError, NoReplyError
from .app import EXIT_USAGE, Settings, command, emit, err, fail, say_error

if TYPE_CHECKING:  # the client library is imported when a command connects
    from ..blocking import Client
    from ..manual_ops import AxisState

EXIT_WAIT_TIMEOUT = 5
AxesArgument = typer.Argument(..., metavar="AXIS...", help="Axis names (X Y Z) or indices, homed together.")


def _hold(c: Client, axis: str, direction: str, channel: int,
          timeout_s: float | None) -> AxisState:
    """Hold the jog key pressed by ``c.jog(..., continuous=True)``, renewed every
    ``RENEW_S`` (the service's dead-man releases a key that is not: docs/manual.md), until
    the axis stands (its software limit), Ctrl-C or ``timeout_s``; then release it."""
    import time

    from ..jog_hold import RENEW_S  # here: ``cnc --help`` imports no asyncio

    deadline = None if timeout_s is None else time.monotonic() + timeout_s
    try:
        while c.axis_state(axis, channel).moving:
            if deadline is not None and time.monotonic() > deadline:
                break  # released below: the timeout ends the jog
            time.sleep(RENEW_S)
            c.renew_jog(axis, direction, channel)
    finally:
        state = c.jog_stop(axis, channel, wait=False)
    return state


def _report(settings: Settings, state: AxisState) -> None:
    if state.limit_warning:
        err.print(f"warning: axis {state.axis} stopped at its software limit", markup=False,
                  emoji=False)
    record: dict[str, Any] = {
        "channel": state.channel, "axis": state.axis, "position_mm": state.position_mm,
        "moving": state.moving, "limit_warning": state.limit_warning,
        "referenced": state.referenced,
    }
    moves = "moving" if state.moving else "stands"
    emit(settings, record,
         f"channel {state.channel}: axis {state.axis} {moves} at {state.position_mm:.4f} mm")


def _fail(exc: AdsError | ClientValueError) -> None:
    """A wait that timed out exits 5 (a request without reply is no wait: 3), else as
    ``fail``."""
    if isinstance(exc, AdsTimeoutError) and not isinstance(exc, NoReplyError):
        say_error(str(exc))
        raise typer.Exit(EXIT_WAIT_TIMEOUT)
    fail(exc)


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
            if stop:
                state = c.jog_stop(axis, channel, wait=not no_wait, timeout_s=timeout_s)
            else:
                state = c.jog(axis, direction, increment_mm=increment_mm, continuous=continuous,
                              handwheel_pulses=handwheel, rapid=rapid, channel=channel,
                              wait=not no_wait, timeout_s=timeout_s)
                if continuous:
                    state = _hold(c, axis, direction, channel, timeout_s)
            _report(settings, state)
    except (AdsError, ClientValueError) as exc:
        _fail(exc)


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
            for state in c.home(axes, channel, timeout_s):
                _report(settings, state)
    except (AdsError, ClientValueError) as exc:
        _fail(exc)
