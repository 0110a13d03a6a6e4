"""What the service says about one object: a browse row, as the client library keeps it."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from cnc_objects.protocol.datatypes import DataType, parse_type
from cnc_objects.protocol.errors import AdsReturnCode

from .errors import AdsError

_BROWSE_FIELDS = 9  # name .. description: what every service sends
_VALUE_NAMES, _SCALE = 9, 10  # the optional fields after them


@dataclass(frozen=True, slots=True)
class Scale:
    """How people read an object's value, as the service describes it: ``raw x factor``
    is the value in ``unit`` (0.1 um x 0.0001 = mm), ``decimals`` its resolution there."""

    unit: str
    factor: float
    decimals: int

    @classmethod
    def from_field(cls, field_: Any) -> Scale | None:
        """The scale of a browse row's eleventh field; None for ``[]``."""
        if not field_:
            return None
        unit, factor, decimals = field_
        if not (isinstance(unit, str) and isinstance(factor, (int, float)) and factor > 0
                and isinstance(decimals, int) and 0 <= decimals <= 15):
            raise ValueError(f"bad scale {field_!r}")
        return cls(unit, float(factor), decimals)


@dataclass(frozen=True, slots=True)
class ObjectInfo:
    """What the service says about one object (a browse row).

    ``enum`` names the values of an enumeration object (``{3: "READY", ...}`` for
    ``ch1.mc_active_state_r``); it is empty for every other object, bit sets included.
    ``scale`` says how people read the value (0.1 um as mm); None for an object without
    one (no unit, an enumeration) or from a service that sends none.
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
    scale: Scale | None = None

    @property
    def engineering_unit(self) -> str:
        """The unit of the value in engineering units (``read(name, units=True)``): the
        scale's (mm for 0.1 um), else the object's own."""
        return self.scale.unit if self.scale is not None else self.unit

    @property
    def dtype(self) -> DataType:
        """The object's data type."""
        return parse_type(self.type)

    @classmethod
    def from_row(cls, row: Any) -> ObjectInfo:
        """The info of one browse descriptor (protocol/frames.py). A row of a service
        without value names (nine fields) has an empty ``enum``, one without a scale (ten)
        no ``scale``; fields after the ones known here are ignored, so a later service may
        add more."""
        try:
            if len(row) < _BROWSE_FIELDS:
                raise ValueError(f"{len(row)} fields, at least {_BROWSE_FIELDS} expected")
            names = row[_VALUE_NAMES] if len(row) > _VALUE_NAMES else []
            scale = Scale.from_field(row[_SCALE]) if len(row) > _SCALE else None
            name, port, group, offset, type_, length, access, unit, description = (
                row[:_BROWSE_FIELDS])
            return cls(name, port, group, offset, type_, length, access, unit, description,
                       {int(v): str(n) for v, n in names}, scale)
        except (TypeError, ValueError) as exc:
            raise AdsError(
                AdsReturnCode.CLIENT_SYNCRESINVALID, f"malformed browse row {row!r:.80}: {exc}"
            ) from None
