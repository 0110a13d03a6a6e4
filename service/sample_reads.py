"""The sampling path's reads: one object's value the short way (issue 37).

A subscription to an object's whole value is resolved once, when it is added, to the
object's getter and encoder (``Probe``); a sampling pass then reads it without the
address space's lookup and the read dispatcher's branches, reads each object once per
pass however many subscriptions share it, and encodes only a value that is not
``unchanged`` from the subscription's last one. An address that is not one object's
whole value (a range of the PLC memory area, a struct, the device data) has no probe:
it is read through the dispatcher as any request is.

Encoding only what changed is exact: a value ``unchanged`` from the last one encodes to
the same bytes, and a changed value is encoded and its bytes compared, so an on-change
subscription still sends exactly when the bytes change.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any

from cnc_objects.protocol.datatypes import DataType

Getter = Callable[[], Any]
Encoder = Callable[[Any], bytes]
#: (port, group, offset, length) -> the getter and encoder that serve a read of it as the
#: dispatcher would, or None when it is not one object's whole value.
ResolveFn = Callable[[int, int, int, int], "tuple[Getter, Encoder] | None"]

#: Types whose equal values encode to equal bytes under one data type. Not float: 0.0 ==
#: -0.0 and NaN != NaN, so a float is the same only as the same object.
_EQUAL_IS_SAME = frozenset({int, bool, str, bytes})


class _Failed:
    """The value of a probe whose getter raised (the dispatcher's read reports it)."""


FAILED = _Failed()


def unchanged(value: Any, last: Any) -> bool:
    """True when ``value`` surely encodes to the bytes ``last`` did: the same object (a
    getter of a fixed-size type gives an immutable number, flag or text), or equal ints
    or texts of the same type; False says nothing (compare the bytes). Snapshots share
    the values of what a cycle did not change, so an unchanged float is the same
    object."""
    if value is last:
        return True
    kind = type(value)
    return kind is type(last) and kind in _EQUAL_IS_SAME and bool(value == last)


def encoder_of(dtype: DataType) -> Encoder:
    """How a read of ``dtype`` encodes a value the CNC produced: ``encode_fitted`` for a
    STRING (made to fit), else ``encode``, with a float of a REAL64 packed at once (the
    most sampled values; ``encode`` checks every other kind and value)."""
    if dtype.kind == "str":
        return dtype.encode_fitted
    encode = dtype.encode
    if dtype.kind == "float" and dtype.size == 8:
        pack = struct.Struct("<d").pack

        def encode_real64(value: Any) -> bytes:
            return pack(value) if type(value) is float else encode(value)

        return encode_real64
    return encode


class Probe:
    """An object's getter and encoder, with the value it read in the latest pass (read
    once per pass, ``value``) and that value's bytes (encoded once, when asked)."""

    __slots__ = ("getter", "encode", "read_no", "value", "data")

    def __init__(self, getter: Getter, encode: Encoder) -> None:
        self.getter = getter
        self.encode = encode
        self.read_no = -1  # the pass whose value ``value`` holds
        self.value: Any = FAILED
        self.data: bytes | None = None  # ``value`` encoded; None: not yet

    def value_in(self, read_no: int) -> Any:
        """The object's value in pass ``read_no`` (the snapshot pinned): read at the first
        call of the pass; ``FAILED`` when the getter raised."""
        if self.read_no != read_no:
            self.read_no, self.data = read_no, None
            try:
                self.value = self.getter()
            except Exception:  # the dispatcher's read logs it and answers its code
                self.value = FAILED
        return self.value

    def encoded(self) -> bytes | None:
        """The bytes of the value ``value_in`` read (encoded once per pass); None when
        it does not encode (the dispatcher's read reports why)."""
        data = self.data
        if data is None:
            try:
                data = self.data = self.encode(self.value)
            except Exception:
                return None
        return data


class Probes:
    """The probes of the subscribed objects, one per object (its getter): subscriptions
    to one object share one read per pass. Bounded by the catalog."""

    def __init__(self, resolve: ResolveFn | None) -> None:
        self._resolve = resolve
        self._by_getter: dict[Getter, Probe] = {}

    def probe(self, port: int, group: int, offset: int, length: int) -> Probe | None:
        """The probe that reads this address, or None (read it through the dispatcher)."""
        if self._resolve is None:
            return None
        found = self._resolve(port, group, offset, length)
        if found is None:
            return None
        getter, encode = found
        probe = self._by_getter.get(getter)
        if probe is None:
            probe = self._by_getter[getter] = Probe(getter, encode)
        return probe
