"""Manual mode of the client, in mm (mixed into ``AsyncClient``): jog and home axes.

    await c.jog("X", "+", increment_mm=0.5)       # MANUAL, one increment, waits, says where
    await c.jog("Y", "-", continuous=True)        # the key stays pressed, renewed ...
    await c.jog_stop("Y")                         # ... until released
    await c.jog("Z", "+", handwheel_pulses=40)    # the handwheel counter moves by 40
    states = await c.home(["X", "Y"])             # homed together; waits until referenced

An axis is its name in the channel (``"X"``) or its index from 1. Each command selects
the channel mode MANUAL when the channel is in another mode, then writes the axis's
manual-mode objects (docs/manual.md) as an HMI does; lengths are mm, converted by the
scale the service gives for each object. What the kernel refuses (channel in ERROR or
HOLD, the axis homing, a value out of range) raises ``AdsError`` with its sentence; a
wait longer than ``timeout_s`` raises ``AdsTimeoutError``. ``cnc jog`` and ``cnc home``
are these methods.

A continuous jog is held only while it is renewed (the service's dead-man, docs/manual.md):
``AsyncClient.jog(..., continuous=True)`` renews the key in the background until
``jog_stop`` (or the connection ends); the blocking ``Client`` has no background, so its
caller calls ``renew_jog`` at least every ``jog_hold.RENEW_S`` (``cnc jog --continuous``
does) or the service releases the key after ``[limits] jog_hold_timeout_s``.
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from cnc_objects.protocol.values import ChannelMode, ManualOperationMode

from . import names
from .client_core import MixinBase
from .errors import AdsTimeoutError, ClientValueError
from .units import engineering

if TYPE_CHECKING:
    from .jog_hold import HeldJog

POLL_S = 0.02  # how often a wait re-reads the axis (wall time)
MAX_AXES = 32  # axes looked for in a channel
DEFAULT_INCREMENT_MM = 1.0  # a jog without another mode: one increment of 1 mm
_DIRECTIONS = {"+": "plus", "-": "minus", 1: "plus", -1: "minus"}


@dataclass(frozen=True, slots=True)
class AxisState:
    """Where an axis of a channel is, after a jog or homing."""

    channel: int
    axis: str  # its name in the channel
    index: int  # from 1
    position_mm: float  # command position, machine coordinates (ACS)
    moving: bool  # manual motion not over
    limit_warning: bool  # stopped at its software limit
    referenced: bool  # homed


class ManualOps(MixinBase):
    """Jog and home (see the module docstring)."""

    async def axis_names(self, channel: int = 1) -> list[str]:
        """The axis names of ``channel``, by axis index from 1."""
        objects = await self.browse(f"ch{channel}.ax*.axis_name")
        values = await self.read_many(o.name for o in objects)
        return [values[o.name] for o in objects]

    async def axis_index(self, axis: str | int, channel: int = 1) -> int:
        """The index (from 1) of ``axis``, given by name (any case) or index;
        ``ClientValueError`` naming the channel's axes when it has none such."""
        names = await self.axis_names(channel)
        text = str(axis).strip()
        if text.isdigit() and 1 <= int(text) <= len(names):
            return int(text)
        for k, name in enumerate(names, start=1):
            if name.upper() == text.upper():
                return k
        raise ClientValueError(f"channel {channel} has no axis {text!r} "
                               f"(axes: {', '.join(names)})")

    async def axis_state(self, axis: str | int, channel: int = 1) -> AxisState:
        """Position (mm), motion, limit warning and homing of an axis."""
        k = await self.axis_index(axis, channel)
        p = f"ch{channel}.ax{k}."
        names = [p + n for n in ("axis_name", "command_position_acs", "manual_moving_r",
                                 "manual_limit_warning_r", "homing_referenced_r")]
        v = await self.read_many(names)
        position_mm = engineering(await self.describe(names[1]), v[names[1]])  # 0.1 um -> mm
        return AxisState(channel, v[names[0]], k, position_mm, bool(v[names[2]]),
                         bool(v[names[3]]), bool(v[names[4]]))

    async def jog(
        self, axis: str | int, direction: str | int = "+", *,
        increment_mm: float | None = None, continuous: bool = False,
        handwheel_pulses: int | None = None, rapid: bool = False, channel: int = 1,
        wait: bool = True, timeout_s: float | None = None,
    ) -> AxisState:
        """Jog ``axis`` in ``direction`` (``"+"``/``"-"`` or 1/-1) in manual mode: by
        ``increment_mm`` (the default: one increment of 1 mm), ``continuous``ly (the key
        stays pressed until ``jog_stop``; no wait), or by ``handwheel_pulses``. With
        ``wait`` (default) returns once the axis stands; ``rapid`` presses the rapid key."""
        chosen = (increment_mm is not None) + continuous + (handwheel_pulses is not None)
        if chosen > 1:
            raise ClientValueError("jog: choose one of increment_mm, continuous, handwheel_pulses")
        key_name = _DIRECTIONS.get(direction)
        if key_name is None:
            raise ClientValueError(f"jog: direction {direction!r}: give + or - (1 or -1)")
        k = await self.axis_index(axis, channel)
        p = f"ch{channel}.ax{k}."
        await self._manual_mode(channel)
        await self.write(p + "manual_rapid_w", rapid)
        key = f"{p}manual_jog_{key_name}_w"
        if handwheel_pulses is not None:
            await self.write(p + "manual_operation_mode_w", int(ManualOperationMode.HANDWHEEL))
            counter = await self.read(p + "manual_handwheel_counter_w")
            sign = 1 if key_name == "plus" else -1
            wrapped = (counter + sign * handwheel_pulses + 2**31) % 2**32 - 2**31  # DINT
            await self.write(p + "manual_handwheel_counter_w", wrapped)
        elif continuous:
            await self.write(p + "manual_operation_mode_w", int(ManualOperationMode.CONTINUOUS))
            await self._hold(key)
            wait = False  # it moves until jog_stop or the software limit
        else:
            await self.write(p + "manual_operation_mode_w", int(ManualOperationMode.INCREMENTAL))
            mm = DEFAULT_INCREMENT_MM if increment_mm is None else increment_mm
            await self.write(p + "manual_increment_w", mm, units=True)
            await self.write(key, True)
            await self.write(key, False)
        if wait:
            await self._wait_standstill(channel, k, timeout_s)
        return await self.axis_state(k, channel)

    async def jog_stop(self, axis: str | int, channel: int = 1, wait: bool = True,
                       timeout_s: float | None = None) -> AxisState:
        """Release both jog keys of ``axis`` (a continuous jog stops); with ``wait``
        (default) returns once it stands."""
        k = await self.axis_index(axis, channel)
        p = f"ch{channel}.ax{k}."
        for key in (p + "manual_jog_plus_w", p + "manual_jog_minus_w"):
            held = self._held_jogs().pop(key, None)
            if held is not None:
                await held.release()  # stops its renewals, writes FALSE
            else:
                await self.write(key, False)
        if wait:
            await self._wait_standstill(channel, k, timeout_s)
        return await self.axis_state(k, channel)

    async def renew_jog(self, axis: str | int, direction: str | int = "+",
                        channel: int = 1) -> None:
        """Renew the held continuous jog key of ``axis`` in ``direction`` (write it TRUE
        again: a key already pressed is no new press). The blocking client's way to hold
        a continuous jog longer than ``[limits] jog_hold_timeout_s``."""
        key_name = _DIRECTIONS.get(direction)
        if key_name is None:
            raise ClientValueError(f"renew_jog: direction {direction!r}: give + or - (1 or -1)")
        k = await self.axis_index(axis, channel)
        await self.write(f"ch{channel}.ax{k}.manual_jog_{key_name}_w", True)

    def _held_jogs(self) -> dict[str, HeldJog]:
        """The keys this client holds and renews in the background (AsyncClient only)."""
        held: dict[str, HeldJog] | None = getattr(self, "_jogs_held", None)
        if held is None:
            held = {}
            self._jogs_held = held
        return held

    async def _hold(self, key: str) -> None:
        """Press ``key``; the ``AsyncClient`` renews it in the background until
        ``jog_stop``. The blocking client drives its calls without a loop: its caller
        renews (``renew_jog``)."""
        from .sync_transport import SyncTransport

        if isinstance(getattr(self, "_t", None), SyncTransport):  # the blocking client
            await self.write(key, True)
            return
        from .jog_hold import HeldJog  # here: the blocking client imports no asyncio

        old = self._held_jogs().pop(key, None)
        if old is not None:
            await old.release()
        held = HeldJog(self, key)
        await held.__aenter__()
        self._held_jogs()[key] = held

    async def home(self, axes: Iterable[str | int] | str | int, channel: int = 1,
                   timeout_s: float | None = None) -> list[AxisState]:
        """Home ``axes`` (one axis or several, started together) in manual mode, to their
        reference positions (P-AXIS-00152); returns once all are referenced."""
        chosen = [axes] if isinstance(axes, (str, int)) else list(axes)
        indices = [await self.axis_index(a, channel) for a in chosen]
        await self._manual_mode(channel)
        for k in indices:
            await self.write(names.ch(channel).ax(k).homing_start_w, True)
        for k in indices:
            await self._wait_standstill(channel, k, timeout_s, homing=True)
        return [await self.axis_state(k, channel) for k in indices]

    async def _manual_mode(self, channel: int) -> None:
        """Select MANUAL unless the channel is in it (the kernel refuses while it works)."""
        if await self.read(names.ch(channel).mc_active_mode_r) != ChannelMode.MANUAL:
            await self.write(names.ch(channel).mc_command_mode_w, int(ChannelMode.MANUAL))

    async def _wait_standstill(self, channel: int, k: int, timeout_s: float | None,
                               homing: bool = False) -> None:
        """Poll until the axis's manual motion is over (and its homing, with ``homing``)."""
        p = f"ch{channel}.ax{k}."
        names = [p + "manual_moving_r"] + ([p + "homing_active_r"] if homing else [])
        deadline = None if timeout_s is None else time.monotonic() + timeout_s
        while any((await self.read_many(names)).values()):
            if deadline is not None and time.monotonic() > deadline:
                raise AdsTimeoutError(f"ch{channel}.ax{k} still moves after {timeout_s:g} s")
            await self._t.pause(POLL_S)

