"""Values for people: an object's raw value in engineering units and back, and numbers
without float noise for JSON.

The service describes how each object is read (``ObjectInfo.scale``, from the catalog's
unit column: 0.1 um -> mm, um/s -> mm/min, 0.1 % -> %), so nothing here knows a factor.
A raw value times the factor is the engineering value, rounded to the object's
resolution (``decimals``): ``1890`` (0.1 um) is ``0.189`` mm, never
``0.18900000000000003``. Values of objects without a scale stay as they are.

For records that are not one object's value (``cnc status``, tool rows), the unit is in
the key's name (``positions_mm``, ``program_time_s``): ``tidy`` rounds each float to the
resolution of that unit, and any other float to 12 significant digits, which removes the
noise of float arithmetic (``0.18900000000007822`` -> ``0.189``) and keeps every digit a
CNC value carries.
"""

from __future__ import annotations

import math
from typing import Any

from .errors import ClientValueError
from .object_info import ObjectInfo, Scale

NOISE_FREE_DIGITS = 12  # significant digits of a float without a known resolution
# unit suffix of a record key -> decimals of its resolution; longest suffix first
_KEY_DECIMALS: tuple[tuple[str, int], ...] = (
    ("_mm_min", 3),
    ("_mm_s", 3),
    ("_mm", 4),  # 0.1 um
    ("_rpm", 3),
    ("_pct", 1),  # 0.1 %
    ("_deg", 4),
    ("_s", 6),  # 1 us
)
_NO_UNIT = ("", "-")  # the catalog's spellings of "no unit"


def round_to(value: float, decimals: int) -> float:
    """``value`` rounded to ``decimals``; its repr is the short one (``0.189``). A value
    that is not finite stays as it is."""
    if not math.isfinite(value):
        return value
    return round(value, decimals) + 0.0  # + 0.0: no "-0.0"


def noise_free(value: float) -> float:
    """``value`` to 12 significant digits: ``0.18900000000007822`` -> ``0.189``."""
    if not math.isfinite(value) or value == 0:
        return value
    return float(f"{value:.{NOISE_FREE_DIGITS}g}")


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _own(value: Any) -> Any:
    """The object's own value, a float without noise."""
    return noise_free(value) if isinstance(value, float) else value


def converts(info: ObjectInfo) -> bool:
    """True when people read the object in another unit than its own (0.1 um as mm);
    False for an object without a scale or one already in mm, mm/s, s (only rounded)."""
    return scale_converts(info.scale, info.unit)


def scale_converts(scale: Scale | None, unit: str) -> bool:
    """``converts`` for an object of ``unit`` with ``scale``."""
    return scale is not None and (scale.unit != unit or scale.factor != 1.0)


def engineering(info: ObjectInfo, raw: Any) -> Any:
    """``raw`` in engineering units, rounded to the object's resolution; a value of an
    object without a scale (a name, a flag, an enumeration) as it is, floats without
    noise."""
    return scaled(info.scale, raw)


def scaled(scale: Scale | None, raw: Any) -> Any:
    """``engineering`` by the scale alone."""
    if scale is None or not _number(raw) or (isinstance(raw, int) and scale.factor == 1.0):
        return _own(raw)  # an integer read in its own unit stays an integer
    return round_to(raw * scale.factor, scale.decimals)


def raw_value(info: ObjectInfo, value: float) -> int | float:
    """The object's own value of ``value`` given in engineering units: an integer for an
    integer object (``75`` % -> ``750``), a float without noise for a REAL."""
    scale = info.scale
    raw = value / scale.factor if scale is not None else value
    if info.dtype.kind == "int":
        return round(raw)
    return noise_free(float(raw))


def parse_engineering(info: ObjectInfo, text: str) -> int | float:
    """``text`` (a number in the object's engineering unit, ``12.5``) as the object's raw
    value; ``ClientValueError`` when it is not a number or out of the object's range."""
    try:
        number = float(text)
    except ValueError:
        try:
            number = int(text, 0)  # 0x hex, as the raw form takes it
        except ValueError:
            unit = info.scale.unit if info.scale is not None else info.unit
            raise ClientValueError(f"{info.name}: {text!r} is not a number of {unit}") from None
    if not math.isfinite(number):
        raise ClientValueError(f"{info.name}: {text!r} is not a finite number")
    raw = raw_value(info, number)
    try:
        info.dtype.encode(raw)  # the range, told in both units: the user gave the first
    except (TypeError, ValueError) as exc:
        dtype = info.dtype
        reason = (f"value {raw} out of range for {dtype.name} ({dtype.minimum}..{dtype.maximum})"
                  if dtype.kind == "int" else str(exc))  # as the client says it for raw
        unit = info.scale.unit if info.scale is not None else info.unit
        raise ClientValueError(f"{info.name}: {text} {unit} = {raw} ({info.unit}): "
                               f"{reason}") from None
    return raw


def value_name(info: ObjectInfo, value: Any) -> str | None:
    """The name of ``value`` when ``info`` is an enumeration (``3`` -> ``READY``)."""
    return info.enum.get(value) if isinstance(value, int) and info.enum else None


def show(info: ObjectInfo, value: Any, raw: bool = False) -> str:
    """``value`` (raw) for people: ``0.1890 mm``, ``75.0 %``, ``3 (READY)``; with ``raw``
    the object's own value and unit: ``1890 (0.1 um)``."""
    named = value_name(info, value)
    if named is not None:
        return f"{value} ({named})"
    scale = info.scale
    if not raw and scale is not None and converts(info) and _number(value):
        return f"{engineering(info, value):.{scale.decimals}f} {scale.unit}"
    own = _own(value) if raw else engineering(info, value)  # rounded to its resolution
    return f"{own} ({info.unit})" if info.unit not in _NO_UNIT else str(own)


def record(info: ObjectInfo, value: Any, raw: bool = False) -> dict[str, Any]:
    """``value`` for JSON: ``{"name", "value", "unit", "raw", "raw_unit"}``, the value in
    engineering units and the object's own beside it; with ``raw``, or for an object
    read in its own unit, ``{"name", "value", "unit"}`` as the object has them. An
    enumeration adds ``"value_name"``."""
    scale = info.scale
    if raw or scale is None or not converts(info) or not _number(value):
        own = _own(value) if raw else engineering(info, value)  # rounded to its resolution
        result = {"name": info.name, "value": own, "unit": info.unit}
    else:
        result = {"name": info.name, "value": engineering(info, value), "unit": scale.unit,
                  "raw": _own(value), "raw_unit": info.unit}
    named = value_name(info, value)
    if named is not None:
        result["value_name"] = named
    return result


def _decimals_of_key(key: str, inherited: int | None) -> int | None:
    """The decimals its unit suffix names (``positions_mm``: 4), else ``inherited``."""
    for suffix, decimals in _KEY_DECIMALS:
        if key.endswith(suffix):
            return decimals
    return inherited


def tidy(data: Any, decimals: int | None = None) -> Any:
    """``data`` (a JSON record) with every float rounded: to the resolution its key's unit
    suffix names (``positions_mm`` and the values under it: 4 decimals), else without
    noise (12 significant digits)."""
    if isinstance(data, float):
        return round_to(data, decimals) if decimals is not None else noise_free(data)
    if isinstance(data, dict):
        return {k: tidy(v, _decimals_of_key(str(k), decimals)) for k, v in data.items()}
    if isinstance(data, (list, tuple)):
        return [tidy(v, decimals) for v in data]
    return data
