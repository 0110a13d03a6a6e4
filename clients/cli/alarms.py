"""``cnc alarms``: list the alarms, watch their events, acknowledge them (docs/alarms.md).

    cnc alarms                    # the active alarms, newest first
    cnc alarms --history          # also the history (cleared ones too)
    cnc alarms --watch            # one line per event: raised, acknowledged, cleared
    cnc alarms ack 7              # acknowledge alarm #7
    cnc alarms ack --all          # acknowledge every active alarm

With ``--json`` every alarm (or event) is one JSON line.
"""

from __future__ import annotations

import contextlib
from typing import TYPE_CHECKING

import typer

from ..errors import AdsError, ClientValueError
from .app import EXIT_USAGE, Settings, app, emit, fail, say_error

if TYPE_CHECKING:  # the client library is imported when a command connects (a quick --help)
    from ..alarm_ops import AlarmInfo
    from ..blocking import Client

alarms_app = typer.Typer(
    no_args_is_help=False,
    help="List the alarms (active, --history), watch them (--watch), acknowledge (ack).",
)
app.add_typer(alarms_app, name="alarms")


def _line(alarm: AlarmInfo) -> str:
    time_text = alarm.time.isoformat(timespec="milliseconds").replace("+00:00", "Z")
    return f"{time_text} {alarm}"


@alarms_app.callback(invoke_without_command=True)
def alarms(
    ctx: typer.Context,
    history: bool = typer.Option(False, "--history", help="Also list the history."),
    watch: bool = typer.Option(
        False, "--watch", help="After the list, print each event as it comes (until "
        "Ctrl-C, --count or --wait-timeout)."),
    count: int = typer.Option(0, "--count", min=0,
                              help="With --watch: stop after COUNT events (0: never)."),
    timeout_s: float = typer.Option(None, "--wait-timeout", min=0.0,
                                    help="With --watch: stop after S seconds."),
) -> None:
    """List the active alarms, newest first: sequence number, state, severity, id,
    channel, file:line:column and text. Acknowledge one with ``cnc alarms ack N``."""
    if ctx.invoked_subcommand is not None:
        return
    settings: Settings = ctx.obj

    listed = settings.call(lambda c: c.alarms(history), "READ alarms")
    if not settings.as_json:
        emit(settings, {}, f"{listed.active_count} active alarm"
             f"{'' if listed.active_count == 1 else 's'}")
    for alarm in listed.active:
        emit(settings, {"list": "active", **alarm.as_dict()}, f"  {_line(alarm)}")
    if history:
        if not settings.as_json:
            emit(settings, {}, f"history ({len(listed.history)}):")
        for alarm in listed.history:
            emit(settings, {"list": "history", **alarm.as_dict()}, f"  {_line(alarm)}")
    if watch:
        _watch(settings, count, timeout_s)


def _watch(settings: Settings, count: int, timeout_s: float | None) -> None:
    import asyncio  # here, not at the top: ``cnc --help`` needs no event loop

    async def run() -> None:
        seen = 0
        async with settings.async_client() as c:
            events = c.alarm_events()
            async with contextlib.aclosing(events):
                async with asyncio.timeout(timeout_s):
                    async for event in events:
                        emit(settings, {"event": event.kind, **event.alarm.as_dict()},
                             f"{event.kind}: {_line(event.alarm)}")
                        seen += 1
                        if count and seen >= count:
                            return

    try:
        asyncio.run(run())
    except KeyboardInterrupt:
        raise typer.Exit(0) from None
    except TimeoutError:
        return  # --wait-timeout: the watch ends
    except (AdsError, ClientValueError) as exc:
        fail(exc)


@alarms_app.command("ack")
def ack(
    ctx: typer.Context,
    sequence: int = typer.Argument(None, help="Sequence number of the alarm (#N in the list)."),
    all_alarms: bool = typer.Option(False, "--all", help="Acknowledge every active alarm."),
) -> None:
    """Acknowledge an alarm (an error stays active until RESET; a warning is cleared)."""
    settings: Settings = ctx.obj
    if (sequence is None) == (not all_alarms):
        say_error("give an alarm's sequence number or --all (one of them)")
        raise typer.Exit(EXIT_USAGE)

    def act(c: Client) -> None:
        if all_alarms:
            c.acknowledge_all_alarms()
        else:
            c.acknowledge_alarm(sequence)

    settings.call(act, "acknowledge alarm")
    what = "every active alarm" if all_alarms else f"alarm #{sequence}"
    emit(settings, {"acknowledged": "all" if all_alarms else sequence},
         f"acknowledged {what}")
