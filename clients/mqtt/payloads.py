"""The bridge's JSON payloads: encode values and replies, decode and check write requests.

Pure functions, no I/O. A value message is

    {"value": 75.0, "unit": "%", "raw": 750, "raw_unit": "0.1 %",
     "ts": "2026-11-21T10:00:00.123456Z", "seq": 17}
    {"value": 3, "name": "READY", "ts": "2026-11-21T10:00:00.123456Z", "seq": 2}

("name" for enumeration objects only, "unit" for objects that have one only; "value" in
engineering units, rounded to the object's resolution, and "raw", "raw_unit" the
object's own, for objects whose scale converts: clients/units.py), a write request
``{"value": 75, "id": "abc"}`` (engineering units; ``{"raw": 750}``: the object's own
value) and its reply ``{"ok": true}`` or
``{"ok": false, "code": "0x704", "error": "ADS 0x704 INVALIDACCESS: ..."}``. Everything
wrong with a request becomes a ``RequestError`` carrying an ADS code, so that the bridge
answers it like any refused write and never stops on it.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import Any

from cnc_objects.protocol.datatypes import DataType
from cnc_objects.protocol.errors import AdsReturnCode, describe_code

from ..object_info import ObjectInfo, Scale
from ..units import converts, raw_value, scale_converts, scaled
from .topics import MAX_ID_CHARS, check_level

#: A request that is not a JSON object with a "value" (ADS: invalid parameter).
MALFORMED = AdsReturnCode.DEVICE_INVALIDPARM
#: A value of the wrong JSON type or out of the object's range (as the client says it).
BAD_VALUE = AdsReturnCode.DEVICE_INVALIDDATA
#: Not writable through this bridge (not in --writable), or a retained request.
REFUSED = AdsReturnCode.DEVICE_INVALIDACCESS

_NO_UNIT = "-"  # what ObjectInfo.unit says for a unitless object


class RequestError(Exception):
    """A write request refused before it reached the service. ``request_id`` is the
    request's id when it could be read (the reply goes there), else None."""

    def __init__(self, code: int, message: str, request_id: str | None = None) -> None:
        super().__init__(f"ADS {describe_code(code)}: {message}")
        self.code = int(code)
        self.request_id = request_id


@dataclass(frozen=True, slots=True)
class SetRequest:
    """A decoded write request: the JSON value as sent, and its id (None: no id).
    ``raw``: the value is the object's own (sent as ``"raw"``), not in engineering units."""

    value: Any
    request_id: str | None
    raw: bool = False


# ------------------------------------------------------------------ values out


def iso_utc(timestamp: datetime) -> str:
    """ISO 8601 in UTC with microseconds and a ``Z``: ``2026-11-21T10:00:00.123456Z``."""
    return timestamp.astimezone(UTC).strftime("%Y-%m-%dT%H:%M:%S.%fZ")


def json_value(value: Any) -> Any:
    """``value`` as JSON can carry it: non-finite reals (which JSON lacks) become null."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def encode_value(
    value: Any, unit: str, timestamp: datetime, seq: int, enum: Mapping[int, str] | None = None,
    scale: Scale | None = None,
) -> bytes:
    """The value message of one sample. ``unit`` as the service describes it: a unitless
    object ("-") gets no "unit" key. ``enum``: the object's value names (``ObjectInfo.enum``);
    an enumeration object gets a "name" key, null for a number the set does not name.
    ``scale`` (``ObjectInfo.scale``): "value" and "unit" are in engineering units, with
    "raw" and "raw_unit" the object's own; a scale in the object's unit only rounds."""
    message: dict[str, Any] = {"value": json_value(scaled(scale, value))}
    if enum:
        message["name"] = enum.get(value)
    if scale is not None and scale_converts(scale, unit):
        message["unit"] = scale.unit
        message["raw"] = json_value(scaled(None, value))  # the object's own, without noise
        message["raw_unit"] = unit
    elif unit not in ("", _NO_UNIT):
        message["unit"] = unit
    message["ts"] = iso_utc(timestamp)
    message["seq"] = seq
    return json.dumps(message, ensure_ascii=False, allow_nan=False).encode()


def encode_ok(topic: str | None = None) -> bytes:
    """The reply to a write the service applied; ``topic`` (the request's) for replies
    without id."""
    if topic is None:
        return b'{"ok": true}'
    return json.dumps({"ok": True, "topic": topic}, ensure_ascii=False).encode()


def format_code(code: int) -> str:
    """An ADS code as the replies carry it: ``0x704``."""
    return f"0x{code:x}"


def encode_error(code: int, error: str, topic: str | None = None) -> bytes:
    """The reply to a refused write; ``topic`` (the request's) for replies without id."""
    message: dict[str, Any] = {"ok": False, "code": format_code(code), "error": error}
    if topic is not None:
        message["topic"] = topic
    return json.dumps(message, ensure_ascii=False).encode()


# ------------------------------------------------------------------ requests in


def _request_id(document: dict[str, Any]) -> str | None:
    if "id" not in document:
        return None
    request_id = document["id"]
    if not isinstance(request_id, str) or len(request_id) > MAX_ID_CHARS:
        raise RequestError(MALFORMED, f'"id" must be a string of 1..{MAX_ID_CHARS} characters')
    try:
        return check_level(request_id, '"id"')
    except ValueError as exc:
        raise RequestError(MALFORMED, f"{exc}: it must fit one topic level") from None


def decode_set(payload: bytes) -> SetRequest:
    """Decode a write request; ``RequestError`` (with the id once known) when malformed.
    The value is "value" (engineering units) or "raw" (the object's own), not both; keys
    other than "value", "raw" and "id" are ignored."""
    try:
        document = json.loads(payload.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise RequestError(MALFORMED, f"the request is not JSON: {exc}") from None
    if not isinstance(document, dict):
        raise RequestError(MALFORMED, 'the request must be a JSON object {"value": ..., "id": ...}')
    request_id = _request_id(document)
    if ("value" in document) == ("raw" in document):
        raise RequestError(MALFORMED, 'the request needs "value" (engineering units) or '
                           '"raw" (the object\'s own value), one of them', request_id)
    if "raw" in document:
        return SetRequest(document["raw"], request_id, raw=True)
    return SetRequest(document["value"], request_id)


def _integral(value: Any) -> int | None:
    """``value`` as an int when it is a JSON integer (750 or 750.0), else None."""
    if isinstance(value, bool):
        return None
    if isinstance(value, int):
        return value
    if isinstance(value, float) and value.is_integer():
        return int(value)
    return None


def _show(value: Any) -> str:
    """A request's value for an error message, cut short: requests come from anyone."""
    text = json.dumps(value, ensure_ascii=False)
    return text if len(text) <= 60 else text[:57] + "..."


def from_engineering(info: ObjectInfo, value: Any) -> Any:
    """The object's own value of a request's ``value`` in engineering units (``75`` % ->
    ``750``); a value of an object read in its own unit, or not a number, as it is (its
    type is checked by ``coerce``)."""
    if not converts(info) or not isinstance(value, (int, float)) or isinstance(value, bool):
        return value
    if not math.isfinite(value):
        return value
    return raw_value(info, value)


def coerce(dtype: DataType, value: Any, what: str) -> Any:
    """The JSON ``value`` as the Python value of ``dtype``: a bool (or 0/1) for BOOLEAN,
    an integer for the integer types, a number for REAL, a string for STRING. Range and
    string length are checked as the client would; ``RequestError`` (0x706) otherwise."""
    converted: bool | int | float | str | None
    match dtype.kind:
        case "bool":
            number = _integral(value)
            converted = value if isinstance(value, bool) else (
                bool(number) if number in (0, 1) else None
            )
        case "int":
            converted = _integral(value)
        case "float":
            ok = isinstance(value, (int, float)) and not isinstance(value, bool)
            converted = float(value) if ok else None
        case _:
            converted = value if isinstance(value, str) else None
    if converted is None:
        expected = {"bool": "true/false", "int": "an integer", "float": "a number"}
        raise RequestError(
            BAD_VALUE,
            f"{what} ({dtype.name}) takes {expected.get(dtype.kind, 'a string')}, "
            f"not {_show(value)}",
        )
    try:
        dtype.encode(converted)  # range, string length and encoding, as the client checks
    except (TypeError, ValueError) as exc:
        raise RequestError(BAD_VALUE, f"{what}: {exc}") from None
    return converted
