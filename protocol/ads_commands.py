"""Payloads of the ADS commands carried in AMS frames (the data after the AMS header).

All integers little-endian, as in Beckhoff's ADS specification::

    command                  request data                          response data
    1 ReadDeviceInfo         -                                     result u32, major u8,
                                                                   minor u8, build u16,
                                                                   name char[16]
    2 Read                   group u32, offset u32, length u32     result u32, length u32,
                                                                   data
    3 Write                  group u32, offset u32, length u32,    result u32
                             data
    4 ReadState              -                                     result u32, ads state
                                                                   u16, device state u16
    5 WriteControl           ads state u16, device state u16,      result u32
                             length u32, data
    6 AddDeviceNotification  group u32, offset u32, length u32,    result u32, handle u32
                             transmission mode u32, max delay
                             u32, cycle time u32 (both in 100 ns),
                             reserved 16 bytes
    7 DeleteDeviceNotif.     handle u32                            result u32
    8 DeviceNotification     length u32, stamps u32, per stamp:    (none: not answered)
      (server to client)     timestamp u64 (FILETIME), samples
                             u32, per sample: handle u32, size
                             u32, data
    9 ReadWrite              group u32, offset u32, read length    result u32, length u32,
                             u32, write length u32, data           data

An error response has the same length as an empty success response of its command
(result != 0, every other field 0, no data): clients such as Beckhoff's AdsLib read the
fixed part of the response before they look at the result, so a shorter reply would make
them lose their place in the stream.

The server side decodes requests into the transport-neutral request tuples of
``frames`` (the dispatcher serves both front ends from them), except
AddDeviceNotification, whose times stay in the 100 ns units ADS gives them.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar, NamedTuple

from .constants import AdsCommand
from .datatypes import STRING_ENCODING
from .errors import AdsReturnCode, ProtocolError
from .frames import (
    DeleteNotificationRequest,
    ReadDeviceInfoRequest,
    ReadRequest,
    ReadStateRequest,
    ReadWriteRequest,
    WriteControlRequest,
    WriteRequest,
)

_U32 = struct.Struct("<I")
_2U32 = struct.Struct("<II")
_3U32 = struct.Struct("<III")
_4U32 = struct.Struct("<IIII")
_ADD = struct.Struct("<IIIIII16s")  # AddDeviceNotification request, 40 bytes
_CONTROL = struct.Struct("<HHI")
_DEVICE_INFO = struct.Struct("<IBBH16s")
_STATE = struct.Struct("<IHH")
_STAMP = struct.Struct("<QI")
DEVICE_NAME_BYTES = 16

_C = AdsCommand


class _AmsAddNotificationFields(NamedTuple):
    invoke_id: int
    port: int
    group: int
    offset: int
    length: int
    transmission_mode: int
    max_delay_100ns: int
    cycle_time_100ns: int


class AmsAddNotificationRequest(_AmsAddNotificationFields):
    """AddDeviceNotification as ADS carries it: ``max_delay_100ns`` and
    ``cycle_time_100ns`` in units of 100 ns (the ZeroMQ frame's ``AddNotificationRequest``
    carries milliseconds)."""

    __slots__ = ()
    COMMAND: ClassVar[AdsCommand] = AdsCommand.ADD_DEVICE_NOTIFICATION


# --------------------------------------------------------------------------- requests


def _size(command: AdsCommand, data: bytes, size: int, invoke_id: int) -> None:
    if len(data) != size:
        raise ProtocolError(
            f"{command.name} carries {size} bytes of data, got {len(data)}",
            invoke_id=invoke_id, command=command, code=AdsReturnCode.DEVICE_INVALIDSIZE,
        )


def _with_data(command: AdsCommand, data: bytes, head: int, announced: int,
               invoke_id: int) -> bytes:
    """The data after a fixed head of ``head`` bytes, which must be ``announced`` long."""
    if len(data) - head != announced:
        raise ProtocolError(
            f"{command.name} announces {announced} bytes of data, carries {len(data) - head}",
            invoke_id=invoke_id, command=command, code=AdsReturnCode.DEVICE_INVALIDSIZE,
        )
    return data[head:]


def _read_device_info(invoke_id: int, port: int, data: bytes) -> Any:
    _size(_C.READ_DEVICE_INFO, data, 0, invoke_id)
    return ReadDeviceInfoRequest(invoke_id, port)


def _read(invoke_id: int, port: int, data: bytes) -> Any:
    if len(data) == 12:  # the hot path
        return ReadRequest(invoke_id, port, *_3U32.unpack(data))
    _size(_C.READ, data, 12, invoke_id)


def _write(invoke_id: int, port: int, data: bytes) -> Any:
    if len(data) < 12:
        _size(_C.WRITE, data, 12, invoke_id)
    group, offset, length = _3U32.unpack_from(data)
    return WriteRequest(invoke_id, port, group, offset,
                        _with_data(_C.WRITE, data, 12, length, invoke_id))


def _read_state(invoke_id: int, port: int, data: bytes) -> Any:
    _size(_C.READ_STATE, data, 0, invoke_id)
    return ReadStateRequest(invoke_id, port)


def _write_control(invoke_id: int, port: int, data: bytes) -> Any:
    if len(data) < 8:
        _size(_C.WRITE_CONTROL, data, 8, invoke_id)
    ads_state, device_state, length = _CONTROL.unpack_from(data)
    return WriteControlRequest(invoke_id, port, ads_state, device_state,
                               _with_data(_C.WRITE_CONTROL, data, 8, length, invoke_id))


def _add_notification(invoke_id: int, port: int, data: bytes) -> Any:
    _size(_C.ADD_DEVICE_NOTIFICATION, data, _ADD.size, invoke_id)
    return AmsAddNotificationRequest(invoke_id, port, *_ADD.unpack(data)[:6])


def _delete_notification(invoke_id: int, port: int, data: bytes) -> Any:
    _size(_C.DELETE_DEVICE_NOTIFICATION, data, 4, invoke_id)
    return DeleteNotificationRequest(invoke_id, port, _U32.unpack(data)[0])


def _read_write(invoke_id: int, port: int, data: bytes) -> Any:
    if len(data) < 16:
        _size(_C.READ_WRITE, data, 16, invoke_id)
    group, offset, read_length, write_length = _4U32.unpack_from(data)
    return ReadWriteRequest(invoke_id, port, group, offset, read_length,
                            _with_data(_C.READ_WRITE, data, 16, write_length, invoke_id))


_REQUEST_DECODERS: dict[int, Callable[[int, int, bytes], Any]] = {
    _C.READ_DEVICE_INFO: _read_device_info,
    _C.READ: _read,
    _C.WRITE: _write,
    _C.READ_STATE: _read_state,
    _C.WRITE_CONTROL: _write_control,
    _C.ADD_DEVICE_NOTIFICATION: _add_notification,
    _C.DELETE_DEVICE_NOTIFICATION: _delete_notification,
    _C.READ_WRITE: _read_write,
}


def decode_request(command: int, invoke_id: int, port: int, data: bytes) -> Any:
    """The request tuple of ``command`` with payload ``data``, addressed to ``port``.

    Raises ``ProtocolError`` with the ADS code to answer: 0x701 for a command the server
    does not take (DeviceNotification included), 0x705 for data of the wrong size."""
    decoder = _REQUEST_DECODERS.get(command)
    if decoder is None:
        raise ProtocolError(
            f"ADS command id {command} is not served", invoke_id=invoke_id, command=command,
            code=AdsReturnCode.DEVICE_SRVNOTSUPP,
        )
    return decoder(invoke_id, port, data)


def encode_read_request(group: int, offset: int, length: int) -> bytes:
    """Read request data."""
    return _3U32.pack(group, offset, length)


def encode_write_request(group: int, offset: int, data: bytes) -> bytes:
    """Write request data."""
    return _3U32.pack(group, offset, len(data)) + data


def encode_write_control_request(ads_state: int, device_state: int, data: bytes = b"") -> bytes:
    """WriteControl request data."""
    return _CONTROL.pack(ads_state, device_state, len(data)) + data


def encode_add_notification_request(
    group: int, offset: int, length: int, transmission_mode: int,
    max_delay_100ns: int, cycle_time_100ns: int,
) -> bytes:
    """AddDeviceNotification request data (40 bytes, the last 16 reserved)."""
    return _ADD.pack(group, offset, length, transmission_mode, max_delay_100ns,
                     cycle_time_100ns, bytes(16))


def encode_delete_notification_request(handle: int) -> bytes:
    """DeleteDeviceNotification request data."""
    return _U32.pack(handle)


def encode_read_write_request(group: int, offset: int, read_length: int, data: bytes) -> bytes:
    """ReadWrite request data."""
    return _4U32.pack(group, offset, read_length, len(data)) + data


# --------------------------------------------------------------------------- responses


def _device_name(name: str) -> bytes:
    """The name in the 16-byte field: CP1252, cut to 15 characters, NUL-padded."""
    return name.encode(STRING_ENCODING, "replace")[: DEVICE_NAME_BYTES - 1]


_RESPONSE_ENCODERS: dict[int, Callable[..., bytes]] = {
    _C.READ_DEVICE_INFO: lambda major, minor, build, name: _DEVICE_INFO.pack(
        0, major, minor, build, _device_name(name)),
    _C.READ: lambda data: _2U32.pack(0, len(data)) + data,
    _C.WRITE: lambda: b"\x00\x00\x00\x00",
    _C.READ_STATE: lambda ads_state, device_state: _STATE.pack(0, ads_state, device_state),
    _C.WRITE_CONTROL: lambda: b"\x00\x00\x00\x00",
    _C.ADD_DEVICE_NOTIFICATION: lambda handle: _2U32.pack(0, handle),
    _C.DELETE_DEVICE_NOTIFICATION: lambda: b"\x00\x00\x00\x00",
    _C.READ_WRITE: lambda data: _2U32.pack(0, len(data)) + data,
}

#: Bytes after the result in an (empty) response of each command: the zeros an error
#: response carries. Commands the server does not serve answer with the result alone.
ERROR_TAIL_BYTES: dict[int, int] = {
    _C.READ_DEVICE_INFO: 1 + 1 + 2 + DEVICE_NAME_BYTES,
    _C.READ: 4,
    _C.WRITE: 0,
    _C.READ_STATE: 2 + 2,
    _C.WRITE_CONTROL: 0,
    _C.ADD_DEVICE_NOTIFICATION: 4,
    _C.DELETE_DEVICE_NOTIFICATION: 0,
    _C.READ_WRITE: 4,
}


def encode_response(command: int, *fields: Any) -> bytes:
    """Successful response data of ``command`` (fields as in the module table, without
    the result)."""
    return _RESPONSE_ENCODERS[command](*fields)


def encode_error_response(command: int, code: int) -> bytes:
    """Error response data: the result ``code``, then zeros to the command's length."""
    return _U32.pack(code) + bytes(ERROR_TAIL_BYTES.get(command, 0))


@dataclass(frozen=True, slots=True)
class DeviceInfo:
    """A decoded ReadDeviceInfo response."""

    result: int
    major: int
    minor: int
    build: int
    name: str


def _decode_device_info(data: bytes) -> DeviceInfo:
    result, major, minor, build, name = _DEVICE_INFO.unpack(data)
    return DeviceInfo(result, major, minor, build,
                      name.split(b"\x00", 1)[0].decode(STRING_ENCODING))


def _decode_with_data(data: bytes) -> tuple[int, bytes]:
    result, length = _2U32.unpack_from(data)
    if len(data) != 8 + length:
        raise ValueError(f"response announces {length} bytes of data, carries {len(data) - 8}")
    return result, data[8:]


_RESPONSE_DECODERS: dict[int, Callable[[bytes], Any]] = {
    _C.READ_DEVICE_INFO: _decode_device_info,
    _C.READ: _decode_with_data,
    _C.WRITE: lambda data: _U32.unpack(data),
    _C.READ_STATE: lambda data: _STATE.unpack(data),
    _C.WRITE_CONTROL: lambda data: _U32.unpack(data),
    _C.ADD_DEVICE_NOTIFICATION: lambda data: _2U32.unpack(data),
    _C.DELETE_DEVICE_NOTIFICATION: lambda data: _U32.unpack(data),
    _C.READ_WRITE: _decode_with_data,
}


def decode_response(command: int, data: bytes) -> Any:
    """A response as the client reads it: a tuple starting with the result (``DeviceInfo``
    for ReadDeviceInfo). Raises ``ValueError`` when the data has the wrong length, which
    for an error response means the server broke the stream (see the module docstring)."""
    decoder = _RESPONSE_DECODERS.get(command)
    if decoder is None:
        raise ValueError(f"ADS command id {command} has no response")
    try:
        return decoder(data)
    except struct.error as exc:
        raise ValueError(f"response to command {command} has the wrong length: {exc}") from None


# --------------------------------------------------------------------------- notifications


@dataclass(frozen=True, slots=True)
class NotificationSample:
    """One sample of a DeviceNotification: the handle it was sent for and the data."""

    handle: int
    data: bytes


@dataclass(frozen=True, slots=True)
class Stamp:
    """Samples that share one timestamp (FILETIME: 100 ns since 1601-01-01 UTC)."""

    timestamp: int
    samples: tuple[NotificationSample, ...]


def encode_notification(samples: list[tuple[int, int, bytes]]) -> bytes:
    """DeviceNotification data for ``(timestamp, handle, data)`` samples: samples with the
    same timestamp are grouped under one stamp, stamps in order of first appearance."""
    stamps: dict[int, list[bytes]] = {}
    for timestamp, handle, data in samples:
        stamps.setdefault(timestamp, []).append(_2U32.pack(handle, len(data)) + data)
    body = b"".join(
        _STAMP.pack(timestamp, len(parts)) + b"".join(parts)
        for timestamp, parts in stamps.items()
    )
    # Length counts what follows it: the stamp count and the stamps.
    return _2U32.pack(4 + len(body), len(stamps)) + body


def decode_notification(data: bytes) -> tuple[Stamp, ...]:
    """The stamps of DeviceNotification data; ``ValueError`` when it is not well formed."""
    try:
        length, count = _2U32.unpack_from(data)
        if length != len(data) - 4:
            raise ValueError(f"notification length {length} != {len(data) - 4} bytes that follow")
        pos, stamps = 8, []
        for _ in range(count):
            timestamp, n_samples = _STAMP.unpack_from(data, pos)
            pos += _STAMP.size
            samples = []
            for _ in range(n_samples):
                handle, size = _2U32.unpack_from(data, pos)
                pos += 8
                if pos + size > len(data):
                    raise ValueError("a sample is longer than the notification")
                samples.append(NotificationSample(handle, data[pos:pos + size]))
                pos += size
            stamps.append(Stamp(timestamp, tuple(samples)))
    except struct.error as exc:
        raise ValueError(f"notification is truncated: {exc}") from None
    if pos != len(data):
        raise ValueError(f"{len(data) - pos} bytes follow the last stamp")
    return tuple(stamps)
