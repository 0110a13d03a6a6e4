"""What an OPC UA variable shows: the CNC objects it is read from and how their values
become its value (and, for a writable one, how a value written becomes the object's).

A ``Source`` is data, declared by the models' modules (``cnc_interface``, later the
MachineTool instances) and bound by ``binding.VariableBinder``. A member the twin cannot
fill is a ``fixed`` source with the reason, which docs/opcua.md repeats member by member.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from asyncua import ua

from .values import engineering_factor, engineering_unit


@dataclass(frozen=True)
class Source:
    """The value of one OPC UA variable.

    ``objects``: the CNC objects it is read from, by name (none: a fixed value);
    ``value``: their raw values (in that order) -> the OPC UA value; ``variant``: its
    type (``array``: a one-dimensional array of it); ``unit``: its engineering unit
    (``EngineeringUnits``), ``limits``: its EURange (low, high); ``write_object``: the
    object a write goes to, ``to_raw``: the value written -> that object's raw value
    (``ValueError``: out of range). ``why``: for a fixed value, why the twin has no
    object for it (docs/opcua.md)."""

    objects: tuple[str, ...]
    value: Callable[..., Any]
    variant: ua.VariantType
    array: bool = False
    unit: str | None = None
    limits: tuple[float, float] | None = None
    write_object: str | None = None
    to_raw: Callable[[Any], Any] | None = None
    why: str = ""


def plain(name: str, variant: ua.VariantType, convert: Callable[[Any], Any] = lambda v: v,
          ) -> Source:
    """One object's value as it is (or through ``convert``)."""
    return Source((name,), convert, variant)


def scaled(name: str, unit: str, limits: tuple[float, float] | None = None,
           write_object: str | None = None, shown_as: str | None = None) -> Source:
    """One object's value in its engineering unit as a Double (``objects.units``: 0.1 um
    -> mm, um/s -> mm/min, 0.1 % -> %); written back (``write_object``) rounded to the
    object's resolution. ``shown_as``: another name of that unit (a rotary axis's
    positions are 0.0001 deg in the same objects: ``deg``)."""
    factor = engineering_factor(unit)
    to_raw = None
    if write_object is not None:
        def to_raw(value: float) -> int:
            if not isinstance(value, float) or value != value:  # NaN
                raise ValueError(f"{value!r} is not a number")
            return round(value / factor)
    return Source((name,), lambda raw: float(raw) * factor, ua.VariantType.Double,
                  unit=shown_as or engineering_unit(unit), limits=limits,
                  write_object=write_object,
                  to_raw=to_raw)


def derived(names: tuple[str, ...], value: Callable[..., Any], variant: ua.VariantType,
            array: bool = False, unit: str | None = None,
            limits: tuple[float, float] | None = None) -> Source:
    """A value computed from several objects (a status from mode and state)."""
    return Source(names, value, variant, array=array, unit=unit, limits=limits)


def fixed(value: Any, variant: ua.VariantType, why: str, unit: str | None = None,
          array: bool = False, limits: tuple[float, float] | None = None) -> Source:
    """A value the twin has no object for; ``why`` says so (docs/opcua.md)."""
    return Source((), lambda: value, variant, array=array, unit=unit, limits=limits, why=why)
