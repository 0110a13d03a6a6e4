"""What the service says about one object: a browse row, as the client library keeps it."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from cnc_objects.protocol.datatypes import DataType, parse_type
from cnc_objects.protocol.errors import AdsReturnCode

from .errors import AdsError

_BROWSE_FIELDS = 9  # name .. description: what every service sends


@dataclass(frozen=True, slots=True)
class ObjectInfo:
    """What the service says about one object (a browse row).

    ``enum`` names the values of an enumeration object (``{3: "READY", ...}`` for
    ``ch1.mc_active_state_r``); it is empty for every other object, bit sets included.
    """

    name: str
    port: int
    group: int
    offset: int
    type: str
    length: int
    access: str
    unit: str
    description: str
    # Not hashed: a dict is not hashable, and the name identifies the object anyway.
    enum: dict[int, str] = field(default_factory=dict, hash=False)

    @property
    def dtype(self) -> DataType:
        """The object's data type."""
        return parse_type(self.type)

    @classmethod
    def from_row(cls, row: Any) -> ObjectInfo:
        """The info of one browse descriptor (protocol/frames.py). A row of a service
        without value names (nine fields) has an empty ``enum``; fields after the ones
        known here are ignored, so a later service may add more."""
        try:
            if len(row) < _BROWSE_FIELDS:
                raise ValueError(f"{len(row)} fields, at least {_BROWSE_FIELDS} expected")
            names = row[_BROWSE_FIELDS] if len(row) > _BROWSE_FIELDS else []
            name, port, group, offset, type_, length, access, unit, description = (
                row[:_BROWSE_FIELDS])
            return cls(name, port, group, offset, type_, length, access, unit, description,
                       {int(v): str(n) for v, n in names})
        except (TypeError, ValueError) as exc:
            raise AdsError(
                AdsReturnCode.CLIENT_SYNCRESINVALID, f"malformed browse row {row!r:.80}: {exc}"
            ) from None
