"""Jogging from the terminal HMI: what the manual-mode keys write (docs/manual.md).

``]`` jogs the jog axis of the current channel in +, ``[`` in -. ``a`` chooses the next
axis, ``i`` the next jog step: 1 um .. 10 mm by increments, then *continuous*. The
choice is shown on the mode bar (``describe``). A jog key selects the channel mode
MANUAL first when the channel is in another mode (the kernel refuses while it works),
then the axis's operation mode (written only when it differs: the kernel changes it at
standstill only).

* **By increments** each press writes the increment and the key pressed and released,
  as an operator panel would: one increment per press; presses during the motion add up.
* **Continuous** jogs while the key is *held*. A terminal reports key presses and the
  keyboard's auto-repeat, never a release, so the HMI presses the panel key
  (``manual_jog_plus_w`` TRUE) at the first press and releases it (FALSE) when the
  repeats stop: ``FIRST_REPEAT_S`` after the first press (the keyboard's delay before it
  repeats), ``REPEAT_GAP_S`` after a repeat. Space releases at once, and so do RESET and
  a key of the other direction or axis (``ContinuousJog``). While held, the key is
  written TRUE again every ``RENEW_S`` (the service's dead-man releases a key that is
  not renewed, docs/manual.md).
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import time
from dataclasses import dataclass

from cnc_objects.clients.client import AsyncClient
from cnc_objects.clients.errors import AdsError
from cnc_objects.clients.jog_hold import RENEW_S
from cnc_objects.protocol.units import UM01_PER_MM
from cnc_objects.protocol.values import ChannelMode, ManualOperationMode

from .machine import AxisView, ChannelView

log = logging.getLogger(__name__)

#: The increments ``i`` steps through (0.1 um units): 1 um, 10 um, 0.1 mm, 1 mm, 10 mm;
#: the step after the last is continuous jog.
INCREMENTS_01UM = (10, 100, 1_000, 10_000, 100_000)
CONTINUOUS = len(INCREMENTS_01UM)  # the JogChoice.increment index of continuous jog
FIRST_REPEAT_S = 0.7  # wall time a key may wait for its first auto-repeat (X11: 660 ms)
REPEAT_GAP_S = 0.2  # wall time between two repeats (auto-repeat is 10..30 per second)


@dataclass(slots=True)
class JogChoice:
    """The HMI's jog selection: axis index in the channel (from 0) and the jog step."""

    axis: int = 0
    increment: int = 3  # index into INCREMENTS_01UM (1 mm); CONTINUOUS: continuous jog

    @property
    def continuous(self) -> bool:
        """Continuous jog (while held), not increments."""
        return self.increment == CONTINUOUS

    @property
    def increment_01um(self) -> int:
        """The chosen increment in 0.1 um (continuous: the largest)."""
        return INCREMENTS_01UM[min(self.increment, CONTINUOUS - 1)]

    def step_text(self) -> str:
        """``1 mm`` or ``continuous``."""
        return "continuous" if self.continuous else f"{self.increment_01um / UM01_PER_MM:g} mm"

    def axis_of(self, channel: ChannelView) -> AxisView:
        """The chosen axis of ``channel``."""
        return channel.axes[min(self.axis, len(channel.axes) - 1)]

    def describe(self, channel: ChannelView | None) -> str:
        """The mode bar's jog line: ``jog ch1.Y 1 mm  ([ ] a i)``."""
        axis = f"ch{channel.id}.{self.axis_of(channel).name}" if channel and channel.axes else "-"
        return f"jog {axis} {self.step_text()}  ([ ] jog, a axis, i step)"

    def next_axis(self, channel: ChannelView) -> str:
        """Choose the channel's next axis; the line the message bar shows."""
        self.axis = (self.axis + 1) % max(1, len(channel.axes))
        return f"ch{channel.id}: jog axis {channel.axes[self.axis].name}"

    def next_increment(self) -> str:
        """Choose the next step; the line the message bar shows."""
        self.increment = (self.increment + 1) % (CONTINUOUS + 1)
        return ("jog continuous (while the key is held)" if self.continuous
                else f"jog increment {self.increment_01um / UM01_PER_MM:g} mm")


async def _prepare(client: AsyncClient, channel: ChannelView, axis: AxisView,
                   operation: ManualOperationMode) -> None:
    """MANUAL and the axis's operation mode, each written only when it differs."""
    if await client.read(channel.obj("mc_active_mode_r")) != ChannelMode.MANUAL:
        await client.write(channel.obj("mc_command_mode_w"), int(ChannelMode.MANUAL))
    if await client.read(axis.obj("manual_operation_mode_w")) != operation:
        await client.write(axis.obj("manual_operation_mode_w"), int(operation))


def _key(axis: AxisView, direction: int) -> str:
    return axis.obj("manual_jog_plus_w" if direction > 0 else "manual_jog_minus_w")


async def jog(client: AsyncClient, channel: ChannelView, choice: JogChoice,
              direction: int) -> str:
    """One increment of the chosen axis in ``direction`` (+1 / -1), in MANUAL."""
    axis = choice.axis_of(channel)
    await _prepare(client, channel, axis, ManualOperationMode.INCREMENTAL)
    await client.write(axis.obj("manual_increment_w"), choice.increment_01um)
    key = _key(axis, direction)
    await client.write(key, True)
    await client.write(key, False)
    sign = "+" if direction > 0 else "-"
    return f"ch{channel.id}: jog {axis.name}{sign}{choice.increment_01um / UM01_PER_MM:g} mm"


@dataclass(slots=True)
class _Held:
    client: AsyncClient
    key: str  # the panel key object pressed
    release_at_s: float  # time.monotonic() when it is released unless a repeat comes


class ContinuousJog:
    """The panel key of a continuous jog, held while the terminal's key repeats."""

    def __init__(self) -> None:
        self.held: _Held | None = None
        self._releaser: asyncio.Task[None] | None = None

    async def press(self, client: AsyncClient, channel: ChannelView, choice: JogChoice,
                    direction: int) -> str:
        """A press or auto-repeat of a jog key: hold the panel key until repeats stop."""
        axis = choice.axis_of(channel)
        key = _key(axis, direction)
        sign = "+" if direction > 0 else "-"
        held = self.held
        if held is not None and held.key == key and held.client is client:
            held.release_at_s = time.monotonic() + REPEAT_GAP_S  # a repeat: keep holding
            return f"ch{channel.id}: jog {axis.name}{sign} (held)"
        await self.release()  # another axis or direction: that key first
        await _prepare(client, channel, axis, ManualOperationMode.CONTINUOUS)
        await client.write(key, True)
        self.held = _Held(client, key, time.monotonic() + FIRST_REPEAT_S)
        self._releaser = asyncio.create_task(self._release_when_repeats_stop())
        return f"ch{channel.id}: jog {axis.name}{sign} continuous, while the key is held"

    async def release(self) -> str:
        """Release the held panel key now (space, RESET); the line the message bar shows."""
        held, self.held = self.held, None
        releaser, self._releaser = self._releaser, None
        if releaser is not None and releaser is not asyncio.current_task():
            releaser.cancel()
            with contextlib.suppress(asyncio.CancelledError):
                await releaser
        if held is None:
            return "jog: no key held"
        await held.client.write(held.key, False)  # releasing is always accepted
        return f"jog released ({held.key})"

    def forget(self) -> None:
        """The session is gone: nothing to release on it (a new service starts released)."""
        self.held = None
        if self._releaser is not None:
            self._releaser.cancel()
            self._releaser = None

    async def _release_when_repeats_stop(self) -> None:
        renew_at_s = time.monotonic() + RENEW_S
        while (held := self.held) is not None:
            now_s = time.monotonic()
            left_s = held.release_at_s - now_s
            if left_s <= 0:
                try:
                    await self.release()
                except AdsError as exc:  # no one awaits this task: log, never raise
                    log.warning("jog key %s not released: %s", held.key, exc)
                return
            if now_s >= renew_at_s:  # the service's dead-man releases a key not renewed
                renew_at_s = now_s + RENEW_S
                try:
                    await held.client.write(held.key, True)
                except AdsError as exc:
                    log.warning("jog key %s not renewed: %s", held.key, exc)
            await asyncio.sleep(min(left_s, max(renew_at_s - time.monotonic(), 0.0)))
