"""Program control and the jog-of-path switchover: what each key writes to the service.

Each operation returns the line the message bar shows when the service accepted it; a
refused write raises ``AdsError`` (the app shows its code and text).
"""

from __future__ import annotations

from cnc_objects.clients.client import AsyncClient

from . import text
from .machine import ChannelView

OVERRIDE_MAX_01PCT = 1000  # the feed override takes 0..100 %
OVERRIDE_STEP_01PCT = 100  # one key press: 10 %


async def select_program(client: AsyncClient, channel: ChannelView, name: str) -> str:
    """Select a program of the store (AUTOMATIC/READY)."""
    await client.write(channel.obj("mc_command_program_name_w"), name)
    return f"ch{channel.id}: selected {name}"


async def start(client: AsyncClient, channel: ChannelView) -> str:
    """START: run the selected program, or resume after feedhold, M0 or a single-block stop."""
    await client.start(channel.id)
    return f"ch{channel.id}: START"


async def hold(client: AsyncClient, channel: ChannelView) -> str:
    """Feedhold."""
    await client.hold(channel.id)
    return f"ch{channel.id}: HOLD"


async def reset(client: AsyncClient, channel: ChannelView) -> str:
    """RESET the channel."""
    await client.reset(channel.id)
    return f"ch{channel.id}: RESET"


async def toggle_single_block(client: AsyncClient, channel: ChannelView) -> str:
    """Single block on when it is off, else off (from the active state, not a local copy)."""
    wanted = not await client.read(channel.obj("mc_active_single_block_r"))
    await client.write(channel.obj("mc_command_single_block_w"), wanted)
    return f"ch{channel.id}: single block {text.on_off(wanted)}"


async def step_override(client: AsyncClient, channel: ChannelView, step_01pct: int) -> str:
    """Change the commanded feed override by ``step_01pct``, held within 0..100 %."""
    now = await client.read(channel.obj("mc_command_feed_override_r"))
    wanted = min(OVERRIDE_MAX_01PCT, max(0, now + step_01pct))
    await client.write(channel.obj("mc_command_feed_override_w"), wanted)
    return f"ch{channel.id}: feed override {text.percent(wanted)}"


async def toggle_suspend(client: AsyncClient, channel: ChannelView) -> str:
    """Suspend the channel's axis output when it is not, else resume it (jog of path).

    The PLC's way (docs/jog-of-path.md): the CNC follows ``command_w`` only while
    ``enable_w`` is TRUE, so ``command_w`` is written first and ``enable_w`` set after it
    when needed, never the other way round (which would apply a stale command).
    """
    names = [channel.suspend("command_w"), channel.suspend("enable_w"), channel.suspend("state_r")]
    values = await client.read_many(names)
    wanted = not values[names[2]]  # toggle what is in effect, not what was commanded
    await client.write(names[0], wanted)
    if not values[names[1]]:
        await client.write(names[1], True)
    return (f"ch{channel.id}: axis output {'suspended' if wanted else 'resumed'} (jog of path)")
