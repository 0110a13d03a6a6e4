"""The spindle of a channel, in rpm and % (mixed into ``AsyncClient``).

    s = await c.spindle()                    # mode, S, commanded and actual rpm, override
    await c.set_spindle_override(80.0)       # %
    await c.start_spindle(1200)              # the manual block S1200 M3; waits for speed
    await c.stop_spindle()                   # M5; waits for standstill

The values are the channel's COM objects ``ch<c>.mc_spindle_*`` and
``ch<c>.mc_techno_<k>_*`` (docs/spindle-plc.md), converted by the scale the service gives
for each (0.001 deg/s -> rpm, 0.1 % -> %). Start and stop are manual blocks, as an ISG
HMI sends them; ``cnc spindle`` is these methods.
"""

from __future__ import annotations

from dataclasses import dataclass

from . import names
from .channel_ops import ChannelOps
from .errors import ClientValueError
from .units import engineering

MODE_NAMES = {1: "M5", 2: "M3", 4: "M4", 8: "M19"}  # mc_spindle_mode_r
SYNC_NAMES = {0: "-", 1: "MOS", 2: "MVS_SVS", 4: "MVS_SNS", 8: "MNS_SNS"}  # mc_techno_k_synch
TYPE_NAMES = {1: "M", 2: "H", 3: "S", 4: "T"}  # mc_techno_k_typ
TECHNO_UNITS = 16  # technology units listed at most


@dataclass(frozen=True, slots=True)
class TechnoUnit:
    """An M/H/S/T function output to the PLC (a technology unit of the channel)."""

    type: str  # M, H, S or T
    number: int
    sync: str  # its synchronisation kind (MOS, MVS_SVS, ...)
    pending: bool  # waits for the PLC's acknowledge


@dataclass(frozen=True, slots=True)
class SpindleStatus:
    """A channel's spindle and its technology units."""

    channel: int
    mode: str  # M3, M4, M5 or M19
    programmed_rpm: float  # S
    commanded_rpm: float  # S x override, signed (+ M3, - M4)
    actual_rpm: float
    override_pct: float
    speed_reached: bool
    units: tuple[TechnoUnit, ...]


class SpindleOps(ChannelOps):
    """The spindle (see the module docstring)."""

    async def spindle(self, channel: int = 1) -> SpindleStatus:
        """The spindle's values and the listed technology units of ``channel``."""
        p = f"ch{channel}.mc_spindle_"
        units = []
        for k in range(TECHNO_UNITS):
            q = f"ch{channel}.mc_techno_{k}_"
            v = await self.read_many(q + n for n in ("typ", "nr", "synch", "state"))
            if not v[q + "typ"]:
                break
            units.append(TechnoUnit(TYPE_NAMES.get(v[q + "typ"], str(v[q + "typ"])), v[q + "nr"],
                                    SYNC_NAMES.get(v[q + "synch"], "?"), bool(v[q + "state"])))
        names = [p + n for n in ("mode_r", "prog_rev_r", "cmd_rev_r", "active_rev_r",
                                 "override_w", "speed_reached_r")]
        v = await self.read_many(names)
        eng = {n: engineering(await self.describe(n), v[n]) for n in names[1:5]}
        return SpindleStatus(channel, MODE_NAMES.get(v[names[0]], "?"), eng[names[1]],
                             eng[names[2]], eng[names[3]], eng[names[4]], bool(v[names[5]]),
                             tuple(units))

    async def set_spindle_override(self, percent: float, channel: int = 1) -> None:
        """Set the spindle override (%, 0..150)."""
        await self.write(names.ch(channel).mc_spindle_override_w, percent, units=True)

    async def start_spindle(self, rpm: float, ccw: bool = False, channel: int = 1,
                            timeout_s: float | None = None) -> None:
        """Start the spindle at ``rpm`` by the manual block ``S<rpm> M3`` (``ccw``: M4);
        returns when the block is done (with the embedded defaults: speed reached)."""
        if rpm < 0:
            raise ClientValueError(f"spindle speed {rpm:g} rpm: give it >= 0 (ccw=True turns M4)")
        await self.wait_mdi(await self.mdi(f"S{rpm:g} {'M4' if ccw else 'M3'}", channel),
                            channel, timeout_s)

    async def stop_spindle(self, channel: int = 1, timeout_s: float | None = None) -> None:
        """Stop the spindle by the manual block M5; returns at standstill."""
        await self.wait_mdi(await self.mdi("M5", channel), channel, timeout_s)
