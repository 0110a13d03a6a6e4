"""CNC object values as OPC UA values: the variant type of each ISG type, engineering
units (EUInformation with UNECE codes) and the scale from the objects' units
(``objects.units``: 0.1 um -> mm, um/s -> mm/min, 0.1 % -> %)."""

from __future__ import annotations

from dataclasses import fields
from datetime import UTC, datetime
from typing import Any

from asyncua import ua

from cnc_objects.objects.units import scale_of
from cnc_objects.protocol.datatypes import DataType
from cnc_objects.protocol.filetime import filetime_to_datetime

#: The OPC UA variant of an ISG type (by name; STRING(n) by kind).
_VARIANTS: dict[str, ua.VariantType] = {
    "BOOLEAN": ua.VariantType.Boolean,
    "UNS8": ua.VariantType.Byte,
    "SGN8": ua.VariantType.SByte,
    "UNS16": ua.VariantType.UInt16,
    "SGN16": ua.VariantType.Int16,
    "UNS32": ua.VariantType.UInt32,
    "SGN32": ua.VariantType.Int32,
    "UNS64": ua.VariantType.UInt64,
    "SGN64": ua.VariantType.Int64,
    "REAL32": ua.VariantType.Float,
    "REAL64": ua.VariantType.Double,
}

source_time = filetime_to_datetime  # a sample's FILETIME as a DataValue's SourceTimestamp

#: Engineering unit (as ``objects.units`` names it) -> UNECE common code (OPC UA Part 8,
#: EUInformation: the unit id is the code's characters packed into an integer).
UNECE_CODES: dict[str, tuple[str, str]] = {
    "mm": ("MMT", "millimetre"),
    "mm/min": ("H81", "millimetre per minute"),
    "mm/s": ("C16", "millimetre per second"),
    "%": ("P1", "percent"),
    "rpm": ("RPM", "revolutions per minute"),
    "deg": ("DD", "degree [unit of angle]"),
    "s": ("SEC", "second [unit of time]"),
    "W": ("WTT", "watt"),
    "N.m": ("NU", "newton metre"),
}
UNECE_NAMESPACE = "http://www.opcfoundation.org/UA/units/un/cefact"


def variant_of(dtype: DataType) -> ua.VariantType:
    """The variant an object of ``dtype`` is served as, unscaled."""
    if dtype.kind == "str":
        return ua.VariantType.String
    return _VARIANTS[dtype.name]


def eu_information(unit: str) -> ua.EUInformation:
    """EUInformation of an engineering unit (``mm``, ``mm/min``, ``%``, ``rpm``, ...)."""
    code, description = UNECE_CODES.get(unit, ("", unit))
    unit_id = 0
    for char in code:
        unit_id = (unit_id << 8) | ord(char)
    return ua.EUInformation(
        NamespaceUri=UNECE_NAMESPACE, UnitId=unit_id if code else -1,
        DisplayName=ua.LocalizedText(unit), Description=ua.LocalizedText(description),
    )


def engineering_factor(unit: str) -> float:
    """Raw object value x factor = the value in its engineering unit (1 without a scale)."""
    scale = scale_of(unit)
    return scale.factor if scale is not None else 1.0


def engineering_unit(unit: str) -> str | None:
    """The engineering unit an object of catalog ``unit`` is read in, None for none."""
    scale = scale_of(unit)
    return scale.unit if scale is not None else None


_DATA_VALUE_FIELDS = tuple(f.name for f in fields(ua.DataValue))


class SharedDataValue(ua.DataValue):  # type: ignore[misc]  # asyncua: Any to mypy
    """A DataValue that is never changed after it is made (each sample, each read makes a
    new one, its value a new object): ``copy.deepcopy`` gives it back as it is. asyncua
    deep-copies every value a monitored item is handed (``MonitoredItemValues``, to keep
    it from a caller that changes it later), 24 us a value here against 3.7 us to encode
    it, on the event loop thread while the kernel's cycle thread waits for the GIL (make
    bench, part opcua, jitter: docs/opcua.md, "Subscriptions measured")."""

    def __deepcopy__(self, memo: dict[int, Any]) -> SharedDataValue:
        return self

    def __eq__(self, other: object) -> bool:  # equal to a plain DataValue of the same fields
        if not isinstance(other, ua.DataValue):
            return NotImplemented
        return all(getattr(self, name) == getattr(other, name) for name in _DATA_VALUE_FIELDS)

    __hash__ = None  # type: ignore[assignment]  # as DataValue's: mutable, compared by value


def good(value: Any, variant: ua.VariantType, when: datetime | None = None) -> ua.DataValue:
    """A Good DataValue of ``value`` as ``variant``, stamped ``when`` (default: now)."""
    now = when or datetime.now(UTC)
    return SharedDataValue(ua.Variant(value, variant), SourceTimestamp=now, ServerTimestamp=now)


def bad(code: int) -> ua.DataValue:
    """A DataValue that carries only the status ``code``."""
    return SharedDataValue(StatusCode=ua.StatusCode(code))
