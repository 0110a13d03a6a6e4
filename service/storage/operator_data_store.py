"""Operator data that survives a restart: each channel's tool list and zero offsets.

ISG keeps the tool data and the zero point data in list files that the start-up list
names (P-STUP-00010 ``werkz_data[i]``, P-STUP-00011 ``nullp_data[i]``) and loads them at
start; a RESET does not touch them. The service does the same with one file in its data
directory (``operator-data.json``, the format of ``objects.operator_data``):

* at start ``load`` reads it and the kernel starts with those tables; a file that cannot
  be read or does not fit the machine is moved aside (``<name>.corrupt-<time>``), the
  log and a warning alarm (``UNREADABLE_ID``) say why, and the configured tables apply;
* the kernel knows no files: it publishes the tables in every snapshot (immutable
  values, replaced by each write). ``observe`` runs in the cycle hook and only compares
  them by identity; a change wakes the writer thread, which writes the newest tables
  (a burst of writes becomes one file write) as a temporary file, fsyncs it and
  renames it over the old one, so that a kill at any moment leaves the old or the new
  file, never a torn one.
"""

from __future__ import annotations

import logging
import os
import threading
import time
from collections.abc import Sequence
from pathlib import Path

from cnc_objects.objects.operator_data import (
    ChannelData,
    OffsetGroup,
    OperatorData,
    OperatorDataError,
    ToolRow,
    dumps,
    loads,
)

from ...protocol.units import UM01_PER_MM
from ..kernel.alarms import AlarmLog
from ..kernel.nc.tool_data import (
    ToolData,
    ToolingTables,
    ToolTable,
    ZeroOffsetTable,
)
from ..kernel.state import ErrorEntry, Snapshot
from ..kernel.tooling import tables_from_config
from ..log_throttle import ThrottledWarning
from ..machine_config import MachineConfig

log = logging.getLogger(__name__)

#: the warning raised when the file kept could not be loaded (project id, KERNEL class)
UNREADABLE_ID = 90002
WRITE_RETRY_S = 1.0  # after a failed write (disk full), the next try waits this long

Tables = tuple[ToolTable, ZeroOffsetTable]


def _value_01um(mm: float) -> float:
    # the tables keep 0.1 um as written; mm from a file give it back to 1e-6 of that
    return round(mm * UM01_PER_MM, 6)


def tables_of(data: OperatorData, machine: MachineConfig) -> list[ToolingTables | None]:
    """Each configured channel's tables from ``data`` (None: the document has no entry
    for it); ``OperatorDataError`` when an entry does not fit the machine."""
    known = {c.id for c in machine.channels}
    for listed in data.channels:
        if listed.channel not in known:
            raise OperatorDataError(f"channel {listed.channel} is not configured "
                                    f"(channels {sorted(known)})")
    out: list[ToolingTables | None] = []
    for cfg in machine.channels:
        entry = data.channel(cfg.id)
        if entry is None:
            out.append(None)
            continue
        start = tables_from_config(machine)
        tools, zero = start.tools, start.zero_offsets
        if entry.tools is not None:
            tools = _tool_table(entry.tools, tools.size, cfg.id)
        if entry.zero_offsets is not None:
            zero = _zero_table(entry.zero_offsets, zero.groups,
                               [a.name.upper() for a in cfg.axes], cfg.id)
        out.append(ToolingTables(tools, zero, start.tool_change_time_s))
    return out


def _tool_table(rows: Sequence[ToolRow], size: int, channel: int) -> ToolTable:
    table: dict[int, ToolData] = {}
    for row in rows:
        if row.wz > size:
            raise OperatorDataError(f"channel {channel}: wz[{row.wz}] is beyond the tool "
                                    f"list (1..{size})")
        table[row.wz] = ToolData(row.valid, _value_01um(row.radius_mm),
                                 _value_01um(row.length_mm), row.name,
                                 _value_01um(row.wear_mm), row.life_max_s)
    return ToolTable(table, size)


def _zero_table(groups: Sequence[OffsetGroup], count: int, axes: list[str],
                channel: int) -> ZeroOffsetTable:
    offsets: dict[int, tuple[float, ...]] = {}
    for group in groups:
        if group.np_grp >= count:
            raise OperatorDataError(f"channel {channel}: np_grp[{group.np_grp}] is beyond "
                                    f"the zero offset table (1..{count - 1})")
        values = [0.0] * len(axes)
        for axis, mm in group.offsets_mm.items():
            if axis not in axes:
                raise OperatorDataError(f"channel {channel}: np_grp[{group.np_grp}] names "
                                        f"axis {axis}; the channel has {', '.join(axes)}")
            values[axes.index(axis)] = _value_01um(mm)
        offsets[group.np_grp] = tuple(values)
    return ZeroOffsetTable(count, offsets)


def data_of(tables: Sequence[Tables], machine: MachineConfig) -> OperatorData:
    """The document of each channel's (tool list, zero offsets): the rows written."""
    channels = []
    for (tools, zero), cfg in zip(tables, machine.channels, strict=True):
        axes = [a.name.upper() for a in cfg.axes]
        rows = tuple(ToolRow(i, r.valid, r.radius_mm, r.length_mm, r.name,
                             r.wear_01um / UM01_PER_MM, r.life_max_s)
                     for i, r in sorted(tools.rows.items()))
        groups = tuple(OffsetGroup(g, {a: zero.offset_mm(g, k) for k, a in enumerate(axes)})
                       for g in sorted(zero.offsets_01um))
        channels.append(ChannelData(cfg.id, rows, groups))
    return OperatorData(tuple(channels))


def write_atomically(path: Path, text: str) -> None:
    """Write ``text`` as ``path``: a temporary file beside it, fsynced, renamed over it,
    and the directory fsynced (the rename itself is durable then)."""
    temporary = path.with_name(path.name + ".tmp")
    with open(temporary, "w", encoding="utf-8") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.replace(temporary, path)
    directory = os.open(path.parent, os.O_RDONLY)
    try:
        os.fsync(directory)
    finally:
        os.close(directory)


class OperatorDataStore:
    """The operator data file of one service: loaded at start, written on each change."""

    def __init__(self, path: Path, machine: MachineConfig) -> None:
        self.path = path
        self._machine = machine
        self._shown: list[Tables] | None = None  # the tables the last observe saw
        self._channels_seen: object = None  # the channels of the snapshot it saw last
        self._latest: list[Tables] | None = None  # to be written (None: nothing new)
        self._changed = threading.Condition()
        self._stopping = False
        self._failed = ThrottledWarning(log, "operator data not written")
        self.writes = 0  # files written since start (cnc_objects tests and figures)
        self._thread: threading.Thread | None = None

    def load(self, alarms: AlarmLog | None = None) -> list[ToolingTables | None]:
        """Each channel's tables from the file (None: the configured ones). A file that
        cannot be used is moved aside, logged and raised as a warning alarm."""
        try:
            text = self.path.read_text(encoding="utf-8")
        except FileNotFoundError:
            log.info("operator data: %s (none yet: the configured tables)", self.path)
            return []
        except (OSError, UnicodeDecodeError) as exc:
            return self._unusable(f"cannot be read ({exc})", alarms)
        try:
            tables = tables_of(loads(text), self._machine)
        except OperatorDataError as exc:
            return self._unusable(str(exc), alarms)
        log.info("operator data: %s (loaded)", self.path)
        return tables

    def _unusable(self, why: str, alarms: AlarmLog | None) -> list[ToolingTables | None]:
        aside = self.path.with_name(f"{self.path.name}.corrupt-{time.strftime('%Y%m%d-%H%M%S')}")
        try:
            os.replace(self.path, aside)
            kept = f"kept as {aside.name}"
        except OSError as exc:
            kept = f"could not be moved aside ({exc.strerror})"
        text = (f"operator data {self.path} not loaded: {why}; {kept}; the configured tool "
                "list and zero offsets apply")
        log.error("%s", text)
        if alarms is not None:
            alarms.raise_error(ErrorEntry(UNREADABLE_ID, text, warning=True), 0)
        return []

    def start(self) -> None:
        """Start the writer thread (the file's directory is made when absent)."""
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:  # each write says so again (throttled); the service runs
            log.error("operator data: cannot make %s (%s)", self.path.parent, exc.strerror)
        self._thread = threading.Thread(target=self._run, name="operator-data-writer",
                                        daemon=True)
        self._thread.start()

    def observe(self, snapshot: Snapshot) -> None:
        """The cycle hook: note tables that changed since the last call (cheap: identity
        only; the writer thread does the rest). A kernel at rest republishes the same
        channels: one comparison then."""
        if snapshot.channels is self._channels_seen:
            return
        self._channels_seen = snapshot.channels
        shown = self._shown
        if shown is not None and all(
            c.tooling.tools is t and c.tooling.zero_offsets_to_keep is z
            for c, (t, z) in zip(snapshot.channels, shown, strict=True)
        ):
            return
        now = [(c.tooling.tools, c.tooling.zero_offsets_to_keep) for c in snapshot.channels]
        self._shown = now
        if shown is None:
            return  # the tables the service started with: in the file already (or configured)
        with self._changed:
            self._latest = now
            self._changed.notify()

    def _run(self) -> None:
        while True:
            with self._changed:
                while self._latest is None and not self._stopping:
                    self._changed.wait()
                latest, self._latest = self._latest, None
                stopping = self._stopping
            if latest is not None:
                self._write(latest)
            if stopping and latest is None:
                return

    def _write(self, tables: list[Tables]) -> None:
        try:
            write_atomically(self.path, dumps(data_of(tables, self._machine)))
            self.writes += 1
        except OSError as exc:
            self._failed.note(f"cannot write {self.path} ({exc}); tried again")
            with self._changed:  # not lost: tried again (a newer change replaces it)
                if self._latest is None and not self._stopping:
                    self._latest = tables
                if not self._stopping:
                    self._changed.wait(WRITE_RETRY_S)

    def close(self, timeout_s: float = 5.0) -> None:
        """Write what changed last, then stop the writer thread."""
        with self._changed:
            self._stopping = True
            self._changed.notify()
        if self._thread is not None:
            self._thread.join(timeout_s)
