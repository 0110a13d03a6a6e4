"""The operator data file: tool list rows and zero offsets as a JSON document.

ISG keeps the tool data and the zero point data of each channel in list files of their
own (P-STUP-00010 ``werkz_data[i]``, P-STUP-00011 ``nullp_data[i]``); the service keeps
them in one file of its data directory (``operator-data.json``), and ``cnc tool
export`` / ``cnc offsets export`` write the same format (docs/manual.md, "Operator data
file"). Pure data: text in, dataclasses out, and back; the service and the CLI do the I/O.

    {"format": "cnc-objects operator data", "version": 1,
     "channels": [{"channel": 1,
                   "tools": [{"wz": 5, "valid": true, "radius_mm": 3.0, "length_mm": 42.0,
                              "name": "drill 6", "wear_mm": 0.01, "life_max_s": 600.0}],
                   "zero_offsets": [{"np_grp": 2, "name": "G55",
                                     "offsets_mm": {"X": 100.0, "Y": 50.0, "Z": -10.0}}]}]}

A channel entry may leave out ``tools`` or ``zero_offsets`` (a tools export has no
offsets): what is left out is not touched when the file is imported. Values are in mm;
a tool's ``name``, ``wear_mm`` and ``life_max_s`` (project fields) are written where set
and read as empty / 0 where absent.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from cnc_objects.protocol.constants import TOOL_LIFE_MAX_S as LIFE_MAX_S
from cnc_objects.protocol.constants import TOOL_NAME_CHARS
from cnc_objects.protocol.units import UM01_PER_MM

FORMAT_NAME = "cnc-objects operator data"
FORMAT_VERSION = 1
#: the largest |value| a table takes, in mm (the SGN32 position objects' 214748.3647 mm)
VALUE_MAX_MM = (2**31 - 1) / UM01_PER_MM


class OperatorDataError(ValueError):
    """The document is not operator data; the message says where and why."""


@dataclass(frozen=True, slots=True)
class ToolRow:
    """One row ``wz[i]`` of a tool list."""

    wz: int
    valid: bool
    radius_mm: float
    length_mm: float
    name: str = ""  # the operator's name of the tool (project, wz[i].name)
    wear_mm: float = 0.0  # radius wear (project, wz[i].wear)
    life_max_s: float = 0.0  # cutting time allowed, 0 = no limit (project, wz[i].life_max)


@dataclass(frozen=True, slots=True)
class OffsetGroup:
    """One zero offset group ``np_grp[i]``: an offset per axis name (mm)."""

    np_grp: int
    offsets_mm: Mapping[str, float]


@dataclass(frozen=True, slots=True)
class ChannelData:
    """A channel's tables; None: the section is not in the document."""

    channel: int
    tools: tuple[ToolRow, ...] | None = None
    zero_offsets: tuple[OffsetGroup, ...] | None = None


@dataclass(frozen=True, slots=True)
class OperatorData:
    """The whole document."""

    channels: tuple[ChannelData, ...]

    def channel(self, channel_id: int) -> ChannelData | None:
        """The entry of channel ``channel_id``, None when the document has none."""
        return next((c for c in self.channels if c.channel == channel_id), None)


def group_name(group: int) -> str:
    """G53..G59 for groups 0..6, ``G159=i`` beyond (a comment in the file)."""
    return f"G{53 + group}" if group <= 6 else f"G159={group}"


def dumps(data: OperatorData) -> str:
    """The document as JSON text, one tool row or offset group a line (ends with a
    newline); ``loads`` reads it back."""
    channels = []
    for ch in data.channels:
        sections = [f'   "channel": {ch.channel}']
        if ch.tools is not None:
            rows = [json.dumps(_tool_fields(r)) for r in ch.tools]
            sections.append(_section("tools", rows))
        if ch.zero_offsets is not None:
            groups = [json.dumps({"np_grp": g.np_grp, "name": group_name(g.np_grp),
                                  "offsets_mm": dict(g.offsets_mm)})
                      for g in ch.zero_offsets]
            sections.append(_section("zero_offsets", groups))
        channels.append("  {\n" + ",\n".join(sections) + "\n  }")
    return (f'{{\n "format": {json.dumps(FORMAT_NAME)},\n "version": {FORMAT_VERSION},\n'
            ' "channels": [\n' + ",\n".join(channels) + "\n ]\n}\n")


def _tool_fields(row: ToolRow) -> dict[str, Any]:
    """A row's fields; name, wear and tool life only where set (older files lack them)."""
    fields: dict[str, Any] = {"wz": row.wz, "valid": row.valid, "radius_mm": row.radius_mm,
                              "length_mm": row.length_mm}
    if row.name:
        fields["name"] = row.name
    if row.wear_mm:
        fields["wear_mm"] = row.wear_mm
    if row.life_max_s:
        fields["life_max_s"] = row.life_max_s
    return fields


def _section(key: str, items: list[str]) -> str:
    if not items:
        return f'   "{key}": []'
    return f'   "{key}": [\n' + ",\n".join(f"    {item}" for item in items) + "\n   ]"


def loads(text: str) -> OperatorData:
    """The document of ``text``; ``OperatorDataError`` naming the first fault."""
    try:
        document = json.loads(text)
    except json.JSONDecodeError as exc:
        raise OperatorDataError(f"not JSON: {exc}") from None
    if not isinstance(document, dict) or document.get("format") != FORMAT_NAME:
        raise OperatorDataError(f'not operator data: "format" must be "{FORMAT_NAME}"')
    if document.get("version") != FORMAT_VERSION:
        raise OperatorDataError(f"version {document.get('version')!r}: this service reads "
                                f"version {FORMAT_VERSION}")
    channels = _list(document, "channels", "the document")
    out = [_channel(c, f"channels[{k}]") for k, c in enumerate(channels)]
    ids = [c.channel for c in out]
    if len(set(ids)) != len(ids):
        raise OperatorDataError(f"channels: a channel is listed twice ({ids})")
    return OperatorData(tuple(out))


def _channel(entry: Any, where: str) -> ChannelData:
    if not isinstance(entry, dict):
        raise OperatorDataError(f"{where}: an object is expected")
    channel = _int(entry, "channel", where, low=1)
    tools = zero = None
    if "tools" in entry:
        tools = tuple(_tool(r, f"{where}.tools[{k}]")
                      for k, r in enumerate(_list(entry, "tools", where)))
        _unique([r.wz for r in tools], f"{where}.tools", "wz")
    if "zero_offsets" in entry:
        zero = tuple(_group(g, f"{where}.zero_offsets[{k}]")
                     for k, g in enumerate(_list(entry, "zero_offsets", where)))
        _unique([g.np_grp for g in zero], f"{where}.zero_offsets", "np_grp")
    return ChannelData(channel, tools, zero)


def _tool(entry: Any, where: str) -> ToolRow:
    if not isinstance(entry, dict):
        raise OperatorDataError(f"{where}: an object is expected")
    valid = entry.get("valid", True)
    if not isinstance(valid, bool):
        raise OperatorDataError(f"{where}.valid: true or false")
    name = entry.get("name", "")
    if not isinstance(name, str) or len(name) >= TOOL_NAME_CHARS:  # the STRING's NUL
        raise OperatorDataError(f"{where}.name: text of at most {TOOL_NAME_CHARS - 1} "
                                "characters")
    life = entry.get("life_max_s", 0.0)
    if isinstance(life, bool) or not isinstance(life, int | float) or not 0 <= life <= LIFE_MAX_S:
        raise OperatorDataError(f"{where}.life_max_s: seconds in 0..{LIFE_MAX_S:g}, not {life!r}")
    return ToolRow(_int(entry, "wz", where, low=1), valid,
                   _mm(entry.get("radius_mm", 0.0), f"{where}.radius_mm", low=0.0),
                   _mm(entry.get("length_mm", 0.0), f"{where}.length_mm"),
                   name, _mm(entry.get("wear_mm", 0.0), f"{where}.wear_mm"), float(life))


def _group(entry: Any, where: str) -> OffsetGroup:
    if not isinstance(entry, dict):
        raise OperatorDataError(f"{where}: an object is expected")
    offsets = entry.get("offsets_mm")
    if not isinstance(offsets, dict):
        raise OperatorDataError(f'{where}.offsets_mm: an object of axis names and mm, '
                                'e.g. {"X": 10.5}')
    return OffsetGroup(_int(entry, "np_grp", where, low=1),
                       {str(axis).upper(): _mm(v, f"{where}.offsets_mm.{axis}")
                        for axis, v in offsets.items()})


def _list(entry: dict[str, Any], key: str, where: str) -> list[Any]:
    value = entry.get(key)
    if not isinstance(value, list):
        raise OperatorDataError(f'{where}: "{key}" must be a list')
    return value


def _int(entry: dict[str, Any], key: str, where: str, low: int) -> int:
    value = entry.get(key)
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        raise OperatorDataError(f"{where}.{key}: a whole number >= {low}, not {value!r}")
    return value


def _mm(value: Any, where: str, low: float = -VALUE_MAX_MM) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise OperatorDataError(f"{where}: a number of mm, not {value!r}")
    if not low <= value <= VALUE_MAX_MM:
        raise OperatorDataError(f"{where}: {value} mm is outside {low:g}..{VALUE_MAX_MM:g} mm")
    return float(value)


def _unique(keys: list[int], where: str, key: str) -> None:
    if len(set(keys)) != len(keys):
        raise OperatorDataError(f"{where}: a {key} is listed twice")
