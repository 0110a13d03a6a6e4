"""Jogging from the terminal HMI: what the manual-mode keys write (docs/manual.md).

A terminal reports key presses, not releases, so the HMI jogs by increments: ``]`` moves
the jog axis of the current channel one increment in +, ``[`` in -. ``a`` chooses the
next axis, ``i`` the next increment (1 um .. 10 mm). A jog key selects the channel mode
MANUAL first when the channel is in another mode (the kernel refuses while it works);
the HMI then writes the axis's operation mode (jog by increments), the increment, and
the key pressed and released, as an operator panel would.
"""

from __future__ import annotations

from dataclasses import dataclass

from cnc_objects.clients.client import AsyncClient

from .machine import ChannelView

MANUAL_MODE = 4  # ChannelMode.MANUAL
INCREMENTAL = 3  # ManualOperationMode.INCREMENTAL
#: The increments ``i`` steps through (0.1 um units): 1 um, 10 um, 0.1 mm, 1 mm, 10 mm.
INCREMENTS_INCR = (10, 100, 1_000, 10_000, 100_000)


@dataclass(slots=True)
class JogChoice:
    """The HMI's jog selection: axis index in the channel (from 0) and the increment."""

    axis: int = 0
    increment: int = 3  # index into INCREMENTS_INCR: 1 mm

    @property
    def increment_incr(self) -> int:
        """The chosen increment in 0.1 um."""
        return INCREMENTS_INCR[self.increment]

    def next_axis(self, channel: ChannelView) -> str:
        """Choose the channel's next axis; the line the message bar shows."""
        self.axis = (self.axis + 1) % max(1, len(channel.axes))
        return f"ch{channel.id}: jog axis {channel.axes[self.axis].name}"

    def next_increment(self) -> str:
        """Choose the next increment; the line the message bar shows."""
        self.increment = (self.increment + 1) % len(INCREMENTS_INCR)
        return f"jog increment {self.increment_incr / 10_000:g} mm"


async def jog(client: AsyncClient, channel: ChannelView, choice: JogChoice,
              direction: int) -> str:
    """One increment of the chosen axis in ``direction`` (+1 / -1), in MANUAL."""
    axis = channel.axes[min(choice.axis, len(channel.axes) - 1)]
    if await client.read(channel.obj("mc_active_mode_r")) != MANUAL_MODE:
        await client.write(channel.obj("mc_command_mode_w"), MANUAL_MODE)
    await client.write(axis.obj("manual_operation_mode_w"), INCREMENTAL)
    await client.write(axis.obj("manual_increment_w"), choice.increment_incr)
    key = axis.obj("manual_jog_plus_w" if direction > 0 else "manual_jog_minus_w")
    await client.write(key, True)
    await client.write(key, False)
    sign = "+" if direction > 0 else "-"
    return f"ch{channel.id}: jog {axis.name}{sign}{choice.increment_incr / 10_000:g} mm"
