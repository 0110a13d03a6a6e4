"""Frames: one msgpack array per ZeroMQ message, mirroring the ADS command field for field.

Layout (every integer unsigned unless noted; ``data`` is raw bytes)::

    request       [invoke_id, command, port, *fields]
    response      [invoke_id, command, result, *fields]
    error reply   [invoke_id, command, result, message]     result != 0
    notification  [0, 8, port, [[handle, sequence, timestamp, data], ...]]

    command                    request fields                         response fields
    1 READ_DEVICE_INFO         -                                      major, minor, build, name
    2 READ                     group, offset, length                  data
    3 WRITE                    group, offset, data                    -
    4 READ_STATE               -                                      ads_state, device_state
    5 WRITE_CONTROL            ads_state, device_state, data          -
    6 ADD_DEVICE_NOTIFICATION  group, offset, length, transmission_mode,
                               max_delay_ms, cycle_time_ms            handle
    7 DELETE_DEVICE_NOTIF.     handle                                 -
    9 READ_WRITE               group, offset, read_length, data       data
    0x100 BROWSE (extension)   pattern                                [descriptor, ...]

A descriptor is ``[name, port, group, offset, type, length, access, unit, description,
values]``; ``values`` names the numbers of an enumeration object as ``[[value, name],
...]`` (``[[1, "DESELECTED"], [2, "SELECTED"], ...]``) and is ``[]`` for every other
object (pairs, not a map: frames allow string map keys only). Services before the value
names sent the first nine fields; a reader takes a missing tenth as ``[]``. An eleventh,
``scale``, is ``[unit, factor, decimals]``: how people read the value (``["mm", 0.0001,
4]`` for 0.1 um: value in mm = raw x factor, resolution 4 decimals), ``[]`` for an object
without one (objects/units.py); a reader takes a missing eleventh as ``[]``.
The ``message`` of an error reply is a project extension: a sentence that says why, next
to the ADS code. Notification timestamps are Windows FILETIME (100 ns since 1601-01-01),
as in ADS: the wall-clock time at which the kernel cycle that produced the value ended.
Invoke id 0 is reserved for notifications; requests use 1..2**32-1.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar, NamedTuple, cast

import msgpack

from .constants import AdsCommand
from .errors import AdsReturnCode, ProtocolError

U32_MAX = 0xFFFFFFFF
_packer = msgpack.Packer(use_bin_type=True, autoreset=True)
_packb = _packer.pack
_array_header = _packer.pack_array_header


def _pack(obj: list[Any]) -> bytes:
    """``obj`` as msgpack bytes (msgpack has no type hints: its ``pack`` returns bytes)."""
    packed: bytes = _packb(obj)
    return packed


# --------------------------------------------------------------------------- requests
# Requests are NamedTuples: immutable, and built from a decoded frame in one call (the
# dispatch hot path). Fields are (invoke_id, port, *command fields); ``FIELDS`` names the
# command fields with their kind, ``COMMAND`` is the ADS command id.


class _RequestFrame:
    """What every request class adds to its fields: its ADS command id, the kinds of its
    command fields, and its encoding. A request class is a NamedTuple of the fields
    (``_<Name>Fields``) with this mixed in: the constants are class variables, not
    fields."""

    __slots__ = ()
    COMMAND: ClassVar[AdsCommand]
    FIELDS: ClassVar[tuple[tuple[str, str], ...]]

    def encode(self) -> bytes:
        """The frame as msgpack bytes."""
        fields = cast("tuple[Any, ...]", self)
        return _pack([fields[0], self.COMMAND, *fields[1:]])


class _ReadDeviceInfoFields(NamedTuple):
    invoke_id: int
    port: int


class ReadDeviceInfoRequest(_ReadDeviceInfoFields, _RequestFrame):
    """Ask for the device name and version."""

    __slots__ = ()
    COMMAND = AdsCommand.READ_DEVICE_INFO
    FIELDS = ()


class _ReadFields(NamedTuple):
    invoke_id: int
    port: int
    group: int
    offset: int
    length: int


class ReadRequest(_ReadFields, _RequestFrame):
    """Read ``length`` bytes at ``group``/``offset``."""

    __slots__ = ()
    COMMAND = AdsCommand.READ
    FIELDS = (("group", "u32"), ("offset", "u32"), ("length", "u32"))


class _WriteFields(NamedTuple):
    invoke_id: int
    port: int
    group: int
    offset: int
    data: bytes


class WriteRequest(_WriteFields, _RequestFrame):
    """Write ``data`` at ``group``/``offset``."""

    __slots__ = ()
    COMMAND = AdsCommand.WRITE
    FIELDS = (("group", "u32"), ("offset", "u32"), ("data", "bytes"))


class _ReadStateFields(NamedTuple):
    invoke_id: int
    port: int


class ReadStateRequest(_ReadStateFields, _RequestFrame):
    """Ask for the ADS state and the device state."""

    __slots__ = ()
    COMMAND = AdsCommand.READ_STATE
    FIELDS = ()


class _WriteControlFields(NamedTuple):
    invoke_id: int
    port: int
    ads_state: int
    device_state: int
    data: bytes


class WriteControlRequest(_WriteControlFields, _RequestFrame):
    """Change the ADS state (RUN, STOP, RESET) and device state."""

    __slots__ = ()
    COMMAND = AdsCommand.WRITE_CONTROL
    FIELDS = (("ads_state", "u32"), ("device_state", "u32"), ("data", "bytes"))


class _AddNotificationFields(NamedTuple):
    invoke_id: int
    port: int
    group: int
    offset: int
    length: int
    transmission_mode: int
    max_delay_ms: int
    cycle_time_ms: int


class AddNotificationRequest(_AddNotificationFields, _RequestFrame):
    """Subscribe to ``length`` bytes at ``group``/``offset``."""

    __slots__ = ()
    COMMAND = AdsCommand.ADD_DEVICE_NOTIFICATION
    FIELDS = (
        ("group", "u32"),
        ("offset", "u32"),
        ("length", "u32"),
        ("transmission_mode", "u32"),
        ("max_delay_ms", "u32"),
        ("cycle_time_ms", "u32"),
    )


class _DeleteNotificationFields(NamedTuple):
    invoke_id: int
    port: int
    handle: int


class DeleteNotificationRequest(_DeleteNotificationFields, _RequestFrame):
    """End the subscription ``handle``."""

    __slots__ = ()
    COMMAND = AdsCommand.DELETE_DEVICE_NOTIFICATION
    FIELDS = (("handle", "u32"),)


class _ReadWriteFields(NamedTuple):
    invoke_id: int
    port: int
    group: int
    offset: int
    read_length: int
    data: bytes


class ReadWriteRequest(_ReadWriteFields, _RequestFrame):
    """Write ``data``, then read ``read_length`` bytes, at ``group``/``offset``."""

    __slots__ = ()
    COMMAND = AdsCommand.READ_WRITE
    FIELDS = (("group", "u32"), ("offset", "u32"), ("read_length", "u32"), ("data", "bytes"))


class _BrowseFields(NamedTuple):
    invoke_id: int
    port: int
    pattern: str


class BrowseRequest(_BrowseFields, _RequestFrame):
    """Project extension: describe every object whose name matches ``pattern`` (glob)."""

    __slots__ = ()
    COMMAND = AdsCommand.BROWSE
    FIELDS = (("pattern", "str"),)


Request = (
    ReadDeviceInfoRequest
    | ReadRequest
    | WriteRequest
    | ReadStateRequest
    | WriteControlRequest
    | AddNotificationRequest
    | DeleteNotificationRequest
    | ReadWriteRequest
    | BrowseRequest
)

REQUEST_TYPES: dict[int, type[Request]] = {
    int(cls.COMMAND): cls
    for cls in (
        ReadDeviceInfoRequest,
        ReadRequest,
        WriteRequest,
        ReadStateRequest,
        WriteControlRequest,
        AddNotificationRequest,
        DeleteNotificationRequest,
        ReadWriteRequest,
        BrowseRequest,
    )
}
_KIND_TYPES = {"u32": int, "bytes": bytes, "str": str, "list": list}
#: Per command: (frame length, ((python type, is u32), ...)) for the fast shape check.
_SHAPES: dict[int, tuple[int, tuple[tuple[type[Any], bool], ...]]] = {
    command: (3 + len(cls.FIELDS), tuple((_KIND_TYPES[k], k == "u32") for _, k in cls.FIELDS))
    for command, cls in REQUEST_TYPES.items()
}


def _unpack(raw: bytes) -> Any:
    try:
        return msgpack.unpackb(raw, raw=False, use_list=True, strict_map_key=True)
    except (ValueError, msgpack.UnpackException, TypeError) as exc:
        raise ProtocolError(f"frame is not valid msgpack: {exc}") from None


def decode_request(raw: bytes) -> Request:
    """Decode a request frame; raise ``ProtocolError`` (with the invoke id when readable)."""
    obj = _unpack(raw)
    if type(obj) is list and len(obj) >= 3:
        invoke_id, command, port = obj[0], obj[1], obj[2]
        shape = _SHAPES.get(command) if type(command) is int else None
        if (
            shape is not None
            and len(obj) == shape[0]
            and type(invoke_id) is int
            and 0 < invoke_id <= U32_MAX
            and type(port) is int
            and 0 <= port <= 0xFFFF
        ):
            for (kind, is_u32), value in zip(shape[1], obj[3:]):
                if type(value) is not kind or (is_u32 and not 0 <= value <= U32_MAX):
                    break
            else:
                request: Request = REQUEST_TYPES[command](invoke_id, *obj[2:])
                return request
    raise _explain_bad_request(obj)


def _explain_bad_request(obj: Any) -> ProtocolError:
    """The error for a frame the fast path refused, as precise as the frame allows."""
    shape_error = "a request is an array [invoke_id, command, port, ...]"
    if type(obj) is not list or not obj:
        return ProtocolError(shape_error)
    if len(obj) < 3:
        invoke_id = obj[0] if type(obj[0]) is int and 0 < obj[0] <= U32_MAX else None
        command = obj[1] if len(obj) == 2 and type(obj[1]) is int else None
        return ProtocolError(shape_error, invoke_id=invoke_id, command=command)
    invoke_id, command, port = obj[0], obj[1], obj[2]
    if type(invoke_id) is not int or not 0 < invoke_id <= U32_MAX:
        return ProtocolError(f"invoke id must be 1..{U32_MAX}, got {invoke_id!r}")
    if type(command) is not int:
        return ProtocolError("command id must be an integer", invoke_id=invoke_id)
    cls = REQUEST_TYPES.get(command)
    if cls is None:
        return ProtocolError(
            f"command id {command} is not supported",
            invoke_id=invoke_id,
            command=command,
            code=AdsReturnCode.DEVICE_SRVNOTSUPP,
        )
    if type(port) is not int or not 0 <= port <= 0xFFFF:
        return ProtocolError(
            f"port must be 0..65535, got {port!r}", invoke_id=invoke_id, command=command
        )
    fields = cls.FIELDS
    if len(obj) != 3 + len(fields):
        names = ", ".join(n for n, _ in fields) or "no fields"
        return ProtocolError(
            f"{cls.COMMAND.name} takes {len(fields)} fields after the port ({names}), "
            f"got {len(obj) - 3}",
            invoke_id=invoke_id,
            command=command,
        )
    for (name, kind), value in zip(fields, obj[3:]):
        if kind == "u32":
            if type(value) is not int or not 0 <= value <= U32_MAX:
                return ProtocolError(
                    f"field {name} must be an unsigned 32-bit integer, got {value!r}",
                    invoke_id=invoke_id,
                    command=command,
                )
        elif type(value) is not _KIND_TYPES[kind]:
            return ProtocolError(
                f"field {name} must be {kind}, got {type(value).__name__}",
                invoke_id=invoke_id,
                command=command,
            )
    return ProtocolError("malformed request", invoke_id=invoke_id, command=command)


# --------------------------------------------------------------------------- responses


class Response(NamedTuple):
    """A reply: ``result`` is the ADS return code; ``message`` is set on errors only."""

    invoke_id: int
    command: int
    result: int
    fields: tuple[Any, ...] | list[Any] = ()
    message: str = ""

    def encode(self) -> bytes:
        """The frame as msgpack bytes."""
        if self.result:
            return encode_error(self.invoke_id, self.command, self.result, self.message)
        return encode_response(self.invoke_id, self.command, *self.fields)


def encode_request(invoke_id: int, command: int, port: int, fields: tuple[Any, ...]) -> bytes:
    """Encode a request without building its NamedTuple (the client's hot path); the
    bytes are those of ``<Request type>(invoke_id, port, *fields).encode()``."""
    return _pack([invoke_id, command, port, *fields])


def encode_response(invoke_id: int, command: int, *fields: Any) -> bytes:
    """Encode a successful reply without building a ``Response`` (the hot path)."""
    return _pack([invoke_id, command, 0, *fields])


def pack_rows(rows: list[Any]) -> bytes:
    """The rows of a list, packed one at a time, without the list's header (see
    ``encode_rows_response``)."""
    return b"".join([_packb(row) for row in rows])


def encode_rows_response(invoke_id: int, command: int, rows: list[Any],
                         packed_rows: bytes | None = None) -> bytes:
    """``encode_response(invoke_id, command, rows)`` byte for byte, packed one row at a
    time (or ``packed_rows``: ``pack_rows(rows)`` kept from before). Why: msgpack packs a
    list in one C call that holds the GIL throughout; the whole catalogue (a browse of
    ``*``: 4 000 rows, 0.6 MB) held it for 1.5-4 ms, and the realtime cycle waited that
    long for it (docs/kernel.md, "What delays the realtime cycle"). Between two rows the
    interpreter hands the GIL to a thread that asks."""
    head: bytes = (_array_header(4) + _packb(invoke_id) + _packb(command) + _packb(0)
                   + _array_header(len(rows)))
    return head + (pack_rows(rows) if packed_rows is None else packed_rows)


def encode_error(invoke_id: int, command: int, code: int, message: str) -> bytes:
    """Encode an error reply carrying the ADS code and a sentence that says why."""
    return _pack([invoke_id, command, int(code), message])


@dataclass(frozen=True, slots=True)
class RawSample:
    """One notification sample: handle, sequence number, FILETIME timestamp, raw data."""

    handle: int
    sequence: int
    timestamp: int
    data: bytes


def encode_notification(port: int, samples: list[list[Any]]) -> bytes:
    """Encode samples ``[[handle, sequence, timestamp, data], ...]`` as one frame."""
    return _pack([0, AdsCommand.DEVICE_NOTIFICATION, port, samples])


@dataclass(frozen=True, slots=True)
class Notification:
    """An unsolicited server frame with one or more samples."""

    port: int
    samples: tuple[RawSample, ...]


def decode_incoming(raw: bytes) -> Response | Notification:
    """Decode a frame a client receives: a response or a notification."""
    obj = _unpack(raw)
    if type(obj) is not list or len(obj) < 3:
        raise ProtocolError("a reply is an array [invoke_id, command, result, ...]")
    invoke_id, command = obj[0], obj[1]
    result = obj[2]
    if (type(result) is int and result == 0 and type(invoke_id) is int and invoke_id > 0
            and type(command) is int):
        return Response(invoke_id, command, 0, obj[3:])  # the common case, checked cheaply
    if invoke_id == 0 and command == AdsCommand.DEVICE_NOTIFICATION:
        if len(obj) != 4 or type(obj[3]) is not list:
            raise ProtocolError("a notification is [0, 8, port, [samples]]")
        samples = []
        for s in obj[3]:
            if (
                type(s) is not list
                or len(s) != 4
                or type(s[0]) is not int
                or type(s[1]) is not int
                or type(s[2]) is not int
                or type(s[3]) is not bytes
            ):
                raise ProtocolError("a sample is [handle, sequence, timestamp, data]")
            samples.append(RawSample(*s))
        return Notification(obj[2], tuple(samples))
    if type(invoke_id) is not int or type(command) is not int or type(obj[2]) is not int:
        raise ProtocolError("invoke id, command and result must be integers")
    if obj[2]:
        message = obj[3] if len(obj) > 3 and type(obj[3]) is str else ""
        return Response(invoke_id, command, obj[2], (), message)
    return Response(invoke_id, command, 0, obj[3:])
