"""Program store and channel operations of the client (mixed into ``AsyncClient``).

    await c.upload("part.nc", Path("part.nc").read_bytes())
    await c.run_program("part.nc", channel=1)          # select + START
    status = await c.wait_program(channel=1, timeout_s=60)
    await c.mdi("G1 X10 F600", channel=1)

Everything goes through objects and the program-store index group; nothing here knows
the kernel. Waiting polls the channel's objects every ``POLL_S`` of wall time.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, fields
from typing import Any

from protocol.constants import MAX_DATA_BYTES, PROGRAM_STORE_GROUP, CncPort
from protocol.constants import ProgramStoreOffset as Op
from protocol.datatypes import STRING_ENCODING

from .errors import AdsTimeoutError, ChannelError

POLL_S = 0.01  # how often waiting re-reads the channel state (wall time)

MODES = {1: "STANDBY", 2: "AUTOMATIC", 3: "MDI", 4: "MANUAL", 5: "REFERENCE"}
STATES = {1: "DESELECTED", 2: "SELECTED", 3: "READY", 4: "ACTIVE", 5: "HOLD", 6: "ERROR"}
_ACTIVE, _HOLD, _ERROR = 4, 5, 6
_ERROR_SLOTS = 8


@dataclass(frozen=True, slots=True)
class ProgramEntry:
    """A file in the service's program store."""

    name: str
    size_bytes: int
    mtime_s: float


CONTOUR_RESPONSE_BLOCKS = 32  # gpCh[i].contour_lookahead.response.block[0..31]
CONTOUR_BLOCK_TYPES = {
    1: "linear", 2: "circular", 3: "LOG ON", 4: "LOG PARAM", 5: "LOG OFF", 6: "polynomial",
}


@dataclass(frozen=True, slots=True)
class ContourBlock:
    """One element of a contour look-ahead reply, in HLI units (0.1 um, rad)."""

    block_type: int
    block_number: int
    block_count_r: int
    start_position: float
    length: float
    programmed_radius: float
    compensated_radius: float
    circle_angle: float
    length_min: float
    tangent_variation: float


CONTOUR_BLOCK_FIELDS = tuple(f.name for f in fields(ContourBlock))  # the HLI field names


@dataclass(frozen=True, slots=True)
class ContourReply:
    """The CNC's answer to a contour look-ahead request, with the unit's state."""

    max_dist_prog_start: float  # 0.1 um
    count_logged_blocks: int
    log_active: bool
    blocks: list[ContourBlock]  # up to the first entry of block_type 0


@dataclass(frozen=True, slots=True)
class ChannelStatus:
    """What ``cnc status`` shows of a channel."""

    channel: int
    mode: str
    state: str
    program: str
    file: str
    line: int
    block_number: int
    positions_mm: dict[str, float]
    path_velocity_mm_s: float
    program_time_s: float
    errors: list[str]


def _name_bytes(name: str) -> bytes:
    return name.encode(STRING_ENCODING) + b"\x00"


class ProgramOps:
    """Upload, list, download and delete programs of the service's store."""

    async def upload(self, name: str, data: bytes) -> None:
        """Store ``data`` as ``name``, replacing an older version atomically."""
        await self.write_raw(CncPort.COM, PROGRAM_STORE_GROUP, Op.UPLOAD, _name_bytes(name) + data)

    async def download(self, name: str) -> bytes:
        """The stored content of ``name``."""
        return await self.read_write_raw(
            CncPort.COM, PROGRAM_STORE_GROUP, Op.DOWNLOAD, _name_bytes(name), MAX_DATA_BYTES
        )

    async def programs(self) -> list[ProgramEntry]:
        """Every file in the store, sorted by name."""
        raw = await self.read_raw(CncPort.COM, PROGRAM_STORE_GROUP, Op.LIST, MAX_DATA_BYTES)
        entries = []
        for line in raw.decode("utf-8").splitlines():
            name, size, mtime = line.split("\t")
            entries.append(ProgramEntry(name, int(size), float(mtime)))
        return entries

    async def delete_program(self, name: str) -> None:
        """Remove ``name`` from the store."""
        await self.write_raw(CncPort.COM, PROGRAM_STORE_GROUP, Op.DELETE, _name_bytes(name))


class ChannelOps:
    """Select, start, hold, resume, reset, manual blocks, status, waiting."""

    async def run_program(self, name: str, channel: int = 1) -> None:
        """Select ``name`` (AUTOMATIC) and START it; returns once the channel is ACTIVE."""
        await self.write(f"ch{channel}.mc_command_program_name_w", name)
        await self.write(f"ch{channel}.mc_command_start_w", True)

    async def start(self, channel: int = 1) -> None:
        """START: run the selected program, or resume after feedhold, M0 or single block."""
        await self.write(f"ch{channel}.mc_command_start_w", True)

    async def hold(self, channel: int = 1) -> None:
        """Feedhold: the path decelerates and stops (HOLD)."""
        await self.write(f"ch{channel}.mc_command_hold_w", True)

    async def reset(self, channel: int = 1) -> None:
        """RESET the channel from any state."""
        await self.write(f"ch{channel}.mc_command_reset_w", True)

    async def mdi(self, blocks: str, channel: int = 1) -> int:
        """Run ``blocks`` as manual blocks; returns the count of finished manual blocks
        before this one (``wait_mdi`` waits until it has grown)."""
        before = await self.read(f"ch{channel}.mc_manual_blocks_done_r")
        await self.write(f"ch{channel}.mc_command_manual_block_w", blocks)
        return before

    async def channel_errors(self, channel: int = 1) -> list[str]:
        """The channel's error list as readable lines."""
        count = await self.read(f"ch{channel}.mc_error_count_r")
        fields = ("id", "file", "line", "column", "text", "warning")
        names = [
            f"ch{channel}.mc_error_{k}_{f}_r"
            for k in range(1, min(count, _ERROR_SLOTS) + 1)
            for f in fields
        ]
        if not names:
            return []
        values = await self.read_many(names)
        lines = []
        for k in range(1, min(count, _ERROR_SLOTS) + 1):
            v = [values[f"ch{channel}.mc_error_{k}_{f}_r"] for f in fields]
            where = f"{v[1]}:{v[2]}:{v[3]}: " if v[1] else ""
            lines.append(f"{'warning' if v[5] else 'error'} {v[0]}: {where}{v[4]}")
        return lines

    async def status(self, channel: int = 1) -> ChannelStatus:
        """Mode, state, program, block and axis positions of a channel."""
        axes = [o for o in await self.browse(f"ch{channel}.ax*.command_position_acs")]
        names = [
            f"ch{channel}.{n}"
            for n in (
                "mc_active_mode_r", "mc_active_state_r", "mc_active_program_name_r",
                "mc_active_file_name_r", "mc_active_line_r", "actual_block_number",
                "actual_path_velocity", "program_time",
            )
        ]
        axis_names = [o.name.replace("command_position_acs", "axis_name") for o in axes]
        values = await self.read_many([*names, *axis_names, *(o.name for o in axes)])
        v: list[Any] = [values[n] for n in names]
        positions = {
            values[an]: values[o.name] / 10_000 for an, o in zip(axis_names, axes, strict=True)
        }
        return ChannelStatus(
            channel, MODES.get(v[0], str(v[0])), STATES.get(v[1], str(v[1])), v[2], v[3], v[4],
            v[5], positions, v[6] / 1000, v[7],
            await self.channel_errors(channel) if v[1] == _ERROR else [],
        )

    async def contour_lookahead(
        self, start_position: float = 0.0, length: float = 0.0, *, plc_channel: int = 0
    ) -> ContourReply:
        """Ask the CNC for contour elements ahead (FCT-C40) through the control unit
        ``gpCh[plc_channel].contour_lookahead``: ``length`` 0 is mode 1 (the marked area
        from index ``start_position``), else mode 2 (elements starting in the path window
        [start_position, start_position + length], 0.1 um). Writes the request, sets the
        semaphore (the CNC answers before the write is acknowledged), reads the reply."""
        unit = f"gpCh[{plc_channel}].contour_lookahead"
        await self.write(f"{unit}.request.start_position", float(start_position))
        await self.write(f"{unit}.request.length", float(length))
        await self.write(f"{unit}.semaphor_rw", True)
        state = [f"{unit}.semaphor_rw", f"{unit}.state.max_dist_prog_start",
                 f"{unit}.state.count_logged_blocks", f"{unit}.state.f_log_is_active"]
        names = [
            f"{unit}.response.block[{k}].{field}"
            for k in range(CONTOUR_RESPONSE_BLOCKS)
            for field in CONTOUR_BLOCK_FIELDS
        ]
        values = await self.read_many([*state, *names])
        if values[state[0]]:
            raise AdsTimeoutError(f"{unit}: the CNC has not answered (semaphor_rw still TRUE)")
        blocks = []
        for k in range(CONTOUR_RESPONSE_BLOCKS):
            entry = [values[f"{unit}.response.block[{k}].{f}"] for f in CONTOUR_BLOCK_FIELDS]
            if entry[0] == 0:  # block_type 0 ends the list
                break
            blocks.append(ContourBlock(*entry))
        return ContourReply(values[state[1]], values[state[2]], values[state[3]], blocks)

    async def _wait(self, channel: int, done: Any, timeout_s: float | None) -> None:
        deadline = None if timeout_s is None else time.monotonic() + timeout_s
        names = [f"ch{channel}.mc_active_state_r", f"ch{channel}.mc_manual_blocks_done_r"]
        while True:
            values = await self.read_many(names)
            state, done_count = values[names[0]], values[names[1]]
            if state == _ERROR:
                raise ChannelError(channel, await self.channel_errors(channel))
            if done(state, done_count):
                return
            if deadline is not None and time.monotonic() > deadline:
                raise AdsTimeoutError(
                    f"channel {channel} still {STATES.get(state, state)} after {timeout_s:g} s"
                )
            await self._t.pause(POLL_S)

    async def wait_program(self, channel: int = 1, timeout_s: float | None = None) -> None:
        """Wait until the channel's program has ended (READY); ``ChannelError`` when the
        channel went to ERROR, ``AdsTimeoutError`` after ``timeout_s``."""
        await self._wait(channel, lambda state, _: state not in (_ACTIVE, _HOLD), timeout_s)

    async def wait_mdi(self, before: int, channel: int = 1, timeout_s: float | None = None) -> None:
        """Wait until the manual block written after ``before`` finished blocks is done."""
        await self._wait(
            channel,
            lambda state, count: count > before or state not in (_ACTIVE, _HOLD),
            timeout_s,
        )
