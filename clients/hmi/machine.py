"""What the HMI shows of the machine, discovered from the service's catalog at connect.

Channels are found by ``browse("ch*.mc_active_state_r")`` and their axes by
``browse("ch<c>.ax*.axis_name")``; nothing is configured in the HMI itself, so the same
HMI serves any machine configuration of the service.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from cnc_objects.clients import names
from cnc_objects.clients.client import AsyncClient

_CHANNEL = re.compile(r"ch(\d+)\.mc_active_state_r", re.IGNORECASE)
_AXIS = re.compile(r"ch(\d+)\.ax(\d+)\.axis_name", re.IGNORECASE)
ROTARY_AXIS_TYPE = 2  # ch<c>.ax<a>.axis_type of a rotary axis (ACHSTYP_ROTATOR)


@dataclass(frozen=True, slots=True)
class AxisView:
    """One axis of a channel: ``ch<channel>.ax<index>``, driving physical axis ``drive``."""

    channel: int
    index: int
    name: str
    drive: int  # physical axis the axis links to (kopf.link_to); 0 = none
    rotary: bool = False  # kenngr.achs_typ 2: positions in degrees

    @property
    def unit(self) -> str:
        """The unit of the axis's positions: "mm", or "°" for a rotary axis."""
        return "°" if self.rotary else "mm"

    @property
    def key(self) -> str:
        """Row key of the axis (``ch1.ax2``)."""
        return f"ch{self.channel}.ax{self.index}"

    def obj(self, leaf: str) -> str:
        """Name of the axis object ``leaf`` (``ch1.ax2.link_state``)."""
        return f"{self.key}.{leaf}"


@dataclass(frozen=True, slots=True)
class ChannelView:
    """One channel: its id (``ch<id>``), its PLC position (``gpCh[plc_index]``), its axes."""

    id: int
    plc_index: int
    axes: tuple[AxisView, ...]

    @property
    def key(self) -> str:
        """Row key of the channel (``ch1``)."""
        return f"ch{self.id}"

    def obj(self, leaf: str) -> str:
        """Name of the channel object ``leaf`` (``ch1.mc_active_state_r``)."""
        return f"ch{self.id}.{leaf}"

    def suspend(self, element: str) -> str:
        """Element of the channel's suspend-axis-output control unit (jog of path)."""
        return f"gpCh[{self.plc_index}].bahn_mc_control.suspend_axis_output.{element}"


@dataclass(frozen=True, slots=True)
class Machine:
    """The channels of the service, in configuration order."""

    channels: tuple[ChannelView, ...]

    @property
    def drives(self) -> tuple[int, ...]:
        """Every physical axis some channel axis links to, ascending."""
        return tuple(sorted({a.drive for c in self.channels for a in c.axes if a.drive}))

    def channel(self, position: int) -> ChannelView:
        """The channel at ``position`` (wraps around)."""
        return self.channels[position % len(self.channels)]


async def discover(client: AsyncClient) -> Machine:
    """Channels and axes of the service at ``client``.

    The PLC position of a channel (``gpCh[i]``) is its position in the configuration, and
    browse lists a channel object's instances in configuration order: the position is the
    index in that list (ids need not be 1, 2, ...).
    """
    ids = [
        int(m.group(1))
        for info in await client.browse("ch*.mc_active_state_r")
        if (m := _CHANNEL.fullmatch(info.name))
    ]
    channels = []
    for position, channel in enumerate(ids):
        found = sorted(
            int(m.group(2))
            for info in await client.browse(f"ch{channel}.ax*.axis_name")
            if (m := _AXIS.fullmatch(info.name)) and int(m.group(1)) == channel
        )
        wanted = [f"ch{channel}.ax{a}.{leaf}" for a in found
                  for leaf in ("axis_name", "requested_link_to_physical_axis", "axis_type")]
        values = await client.read_many(wanted) if wanted else {}
        axes = tuple(
            AxisView(channel, a, values[names.ch(channel).ax(a).axis_name] or f"ax{a}",
                     values[names.ch(channel).ax(a).requested_link_to_physical_axis],
                     values[names.ch(channel).ax(a).axis_type] == ROTARY_AXIS_TYPE)
            for a in found
        )
        channels.append(ChannelView(channel, position, axes))
    return Machine(tuple(channels))
