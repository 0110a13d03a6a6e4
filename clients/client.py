"""The client API: ``AsyncClient`` (asyncio) and ``Client`` (blocking), one set of methods.

    async with AsyncClient("tcp://127.0.0.1:5555") as c:
        override = await c.read("ch1.mc_command_feed_override_r")
        await c.write("ch1.mc_command_feed_override_w", 500)
        async for sample in c.subscribe("ch1.ax1.link_state"):
            ...

    with Client("tcp://127.0.0.1:5555") as c:
        c.read_address(551, 0x121301, 0x10018, "UNS32")

    # a service started with --keys (docs/security.md): this client's key pair, and the
    # service's public key (default: server.key beside the key file)
    with Client("tcp://cnc:5555", key_file="alice.key_secret", server_key="server.key") as c:
        ...

Objects are found by name through one browse of the service's catalog, cached for the
life of the connection (single flight: calls that need it meanwhile wait for that one
browse; ``find`` looks a name up and no more); an unknown name fails with ADS 0x710 and the nearest names
("did you mean ..."). What the service refuses raises ``AdsError`` naming its ADS code;
a request without reply raises ``NoReplyError`` (an ``AdsTimeoutError``) naming what was
asked (``no reply to READ ch1.x within 5 s from tcp://...``). What the client refuses
before sending anything (a value out of its type's range, an unknown state name) raises
``ClientValueError`` (a ``ValueError``), which claims no ADS code. A service that will not
let the client in (its key refused, or keys that do not fit) raises
``AuthenticationError`` (an ``AdsConnectionError``, ADS 0x723) as soon as it says so.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import AsyncGenerator, AsyncIterator, Coroutine, Iterable, Iterator
from dataclasses import dataclass
from datetime import datetime
from typing import TYPE_CHECKING, Any, Self, TypeVar, cast

from cnc_objects.protocol import sum as sums
from cnc_objects.protocol.constants import AdsState, CncPort, TransmissionMode
from cnc_objects.protocol.constants import ReservedIndexGroup as RIG
from cnc_objects.protocol.datatypes import STRING_ENCODING, DataType, parse_type
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.filetime import filetime_to_datetime
from cnc_objects.protocol.frames import (
    AddNotificationRequest,
    BrowseRequest,
    DeleteNotificationRequest,
    ReadDeviceInfoRequest,
    ReadRequest,
    ReadStateRequest,
    ReadWriteRequest,
    Request,
    Response,
    WriteControlRequest,
    WriteRequest,
)

from .alarm_ops import AlarmOps
from .channel_ops import (
    ChannelStatus,
    CheckError,
    CheckResult,
    ProgramEntry,
)
from .client_core import SAMPLE_BUFFER
from .curve import client_curve
from .endpoint import DEFAULT_ENDPOINT as DEFAULT_ENDPOINT  # re-exported: its old home
from .errors import AdsConnectionError, AdsError, ClientValueError, NoReplyError
from .machine_ops import MachineOps
from .object_info import ObjectInfo
from .path_trace import TraceOps
from .sync_transport import SyncTransport, drive
from .units import engineering, raw_value

if TYPE_CHECKING:  # imported where used: the blocking client (cnc read) loads no asyncio
    import asyncio

    from .transport import AsyncTransport

DEFAULT_TIMEOUT_S = 5.0
_HANDLE_PORT = CncPort.COM  # handles are global in the service; any CNC port serves them
SUGGESTIONS = 3  # nearest names offered for an unknown one
# How often the service checks an on-change subscription when the caller names no
# cycle_ms: 10 kernel cycles of 1 ms, 100 samples/s at most for an object that changes
# every cycle (a moving axis sent 1000/s before; issue 36). cycle_ms=0: every cycle.
DEFAULT_ON_CHANGE_CYCLE_MS = 10
DEFAULT_CYCLIC_CYCLE_MS = 100  # a cyclic subscription without cycle_ms
T = TypeVar("T")


@dataclass(frozen=True, slots=True)
class DeviceInfo:
    """ReadDeviceInfo and ReadState in one."""

    name: str
    version: str
    ads_state: AdsState
    device_state: int


@dataclass(frozen=True, slots=True)
class Sample:
    """One notification: the object's value, when the kernel sampled it, its sequence."""

    name: str
    value: Any
    timestamp: datetime
    sequence: int


_TYPES_BY_NAME: dict[str, DataType] = {}


def _coerce_type(dtype: DataType | str) -> DataType:
    if isinstance(dtype, DataType):
        return dtype
    known = _TYPES_BY_NAME.get(dtype)
    if known is not None:
        return known
    try:
        known = _TYPES_BY_NAME[dtype] = parse_type(dtype)
    except ValueError as exc:
        raise ClientValueError(str(exc)) from None
    return known


def _encode(dtype: DataType, value: Any, what: str) -> bytes:
    """``value`` as ``dtype``'s bytes; a value the type cannot hold is refused here,
    before anything is sent (``ClientValueError``)."""
    try:
        return dtype.encode(value)
    except (TypeError, ValueError) as exc:
        if dtype.kind == "int" and type(value) is int:  # the common mistake: say the range
            reason = (f"value {value} out of range for {dtype.name} "
                      f"({dtype.minimum}..{dtype.maximum})")
        else:
            reason = str(exc)
        raise ClientValueError(f"{what}: {reason}") from None


def _ads_state(state: AdsState | int | str) -> int:
    """An ADS state given as ``AdsState``, its number or its name (any case)."""
    if isinstance(state, str):
        try:
            return int(AdsState[state.strip().upper()])
        except KeyError:
            names = ", ".join(s.name for s in AdsState)
            raise ClientValueError(
                f"unknown ADS state {state!r}; the ADS states are {names} "
                "(the service takes RUN, STOP and RESET)") from None
    return int(state)


def _suggest(name: str, known: Iterable[str]) -> str:
    """ ``; did you mean a, b or c?`` for the names nearest to ``name``, else ``""``."""
    import difflib  # only when a name is unknown: not on every client's start

    names = {k.lower(): k for k in known}
    nearest = [names[k] for k in difflib.get_close_matches(name.lower(), names, SUGGESTIONS)]
    if not nearest:
        return ""
    listed = nearest[0] if len(nearest) == 1 else f"{', '.join(nearest[:-1])} or {nearest[-1]}"
    return f"; did you mean {listed}?"


def _decode(dtype: DataType, data: bytes, what: str) -> Any:
    try:
        return dtype.decode(data)
    except ValueError as exc:
        raise AdsError(AdsReturnCode.CLIENT_SYNCRESINVALID, f"{what}: {exc}") from None


def _raw(info: ObjectInfo, value: Any) -> Any:
    """``value`` given in engineering units as the object's own (a number only)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ClientValueError(f"{info.name}: units=True takes a number, not {value!r}")
    return raw_value(info, value)


PathText = str | os.PathLike[str]


class AsyncClient(TraceOps, AlarmOps, MachineOps):
    """Asyncio client of a cnc-objects service. Use with ``async with``.

    ``key_file``: this client's CURVE secret key file (``NAME.key_secret``, or ``NAME.key``
    with the secret beside it), for a service started with ``--keys``; ``server_key``: the
    service's public key file (default: ``server.key`` beside ``key_file``). A key file
    that cannot be used raises ``ClientValueError`` here.

    ``batch`` (default True): the reads and writes issued in one event-loop turn (an
    ``asyncio.gather`` of 64 reads) go out as ADS sum commands, one frame for many, with
    each request's result or error its own (``clients.batching``); False sends every
    request as its own frame.
    """

    def __init__(
        self,
        endpoint: str = DEFAULT_ENDPOINT,
        *,
        timeout_s: float = DEFAULT_TIMEOUT_S,
        key_file: PathText | None = None,
        server_key: PathText | None = None,
        batch: bool = True,
        _transport: AsyncTransport | SyncTransport | None = None,
    ) -> None:
        self.endpoint = endpoint
        if _transport is None:
            from .transport import AsyncTransport

            curve = client_curve(key_file, server_key)
            _transport = AsyncTransport(endpoint, timeout_s, curve=curve, batch=batch)
        self._t = _transport
        self._objects: dict[str, ObjectInfo] | None = None
        self._catalogue_waiters: list[asyncio.Future[None]] | None = None  # a browse is out
        self._handles: dict[str, int] = {}

    async def __aenter__(self) -> AsyncClient:
        await self._t.open()
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self._t.close()

    # ------------------------------------------------------------ plumbing

    async def _call(self, cls: type[Request], port: int, *fields: Any) -> Response:
        """Send one request; return the reply or raise AdsError with its code."""
        reply = await self._t.exchange(cls.COMMAND, port, fields)
        if reply.result:
            raise AdsError(reply.result, reply.message)
        return reply

    def _payload(self, reply: Response, index: int = 0) -> Any:
        try:
            return reply.fields[index]
        except IndexError:
            raise AdsError(AdsReturnCode.CLIENT_SYNCRESINVALID, "reply lacks its data") from None

    def _data(self, reply: Response) -> bytes:
        """The data bytes of a reply (a Read's or a ReadWrite's)."""
        data = self._payload(reply)
        if type(data) is not bytes:
            raise AdsError(AdsReturnCode.CLIENT_SYNCRESINVALID,
                           f"reply data is {type(data).__name__}, not bytes")
        return data

    async def describe(self, name: str) -> ObjectInfo:
        """What the service says about the object ``name`` (cached per connection)."""
        return await self._object(name)

    async def find(self, name: str) -> ObjectInfo | None:
        """The object ``name`` (any case) from the cached catalogue, or None: unlike
        ``describe``, no search for the nearest names (a gateway checking many names its
        users sent can refuse each unknown one in a dictionary look-up)."""
        return (await self._catalogue()).get(name.lower())

    async def _object(self, name: str) -> ObjectInfo:
        catalogue = await self._catalogue()
        info = catalogue.get(name.lower())
        if info is None:
            hint = _suggest(name, (o.name for o in catalogue.values()))
            raise AdsError(AdsReturnCode.DEVICE_SYMBOLNOTFOUND, f"no object {name!r}{hint}")
        return info

    async def _catalogue(self) -> dict[str, ObjectInfo]:
        """The service's objects by lower-case name: one browse for the connection's life,
        single flight: calls that come while it is out wait for it (a cold ``gather`` of
        500 reads browses once, not 500 times)."""
        while self._objects is None:
            if self._catalogue_waiters is not None:  # another call browses: wait for it
                import asyncio  # only an event loop overlaps calls (the blocking client's don't)

                waiter = asyncio.get_running_loop().create_future()
                self._catalogue_waiters.append(waiter)
                await waiter  # its error is ours; a cancelled browse: try again
                continue
            self._catalogue_waiters, error = [], None
            try:
                self._objects = {o.name.lower(): o for o in await self.browse("*")}
            except Exception as exc:  # the waiters get the same error as this call (a
                # cancelled browse is no Exception: they try again, one of them browses)
                error = exc
                raise
            finally:
                waiters, self._catalogue_waiters = self._catalogue_waiters, None
                for waiter in waiters:
                    if waiter.done():
                        continue
                    if error is None:
                        waiter.set_result(None)
                    else:
                        waiter.set_exception(error)
        return self._objects

    # ------------------------------------------------------------ API

    async def info(self) -> DeviceInfo:
        """Device name and version (ReadDeviceInfo) and ADS state (ReadState)."""
        dev = await self._call(ReadDeviceInfoRequest, CncPort.COM)
        state = await self._call(ReadStateRequest, CncPort.COM)
        major, minor, build, name = dev.fields
        return DeviceInfo(name, f"{major}.{minor}.{build}", AdsState(state.fields[0]), state.fields[1])

    async def read_state(self) -> tuple[AdsState, int]:
        """(ADS state, device state)."""
        reply = await self._call(ReadStateRequest, CncPort.COM)
        return AdsState(reply.fields[0]), reply.fields[1]

    async def write_control(self, ads_state: AdsState | int | str, device_state: int = 0) -> None:
        """Command the kernel's ADS state: RUN, STOP or RESET, as ``AdsState.STOP``, its
        number or its name in any case (``"stop"``); an unknown name raises
        ``ClientValueError`` listing the names."""
        await self._call(WriteControlRequest, CncPort.COM, _ads_state(ads_state), device_state, b"")

    async def browse(self, pattern: str = "*") -> list[ObjectInfo]:
        """Descriptions of the objects whose names match the glob ``pattern``."""
        reply = await self._call(BrowseRequest, CncPort.COM, pattern)
        return [ObjectInfo.from_row(row) for row in self._payload(reply)]

    async def read_address(
        self, port: int, group: int, offset: int, dtype: DataType | str
    ) -> Any:
        """Read the value at an ADS address, decoded as ``dtype`` (``"UNS16"``, ...)."""
        dtype = _coerce_type(dtype)
        reply = await self._call(ReadRequest, port, group, offset, dtype.size)
        try:
            return dtype.decode(reply.fields[0])
        except (ValueError, IndexError) as exc:  # the message is built only on this rare path
            raise AdsError(
                AdsReturnCode.CLIENT_SYNCRESINVALID, f"0x{group:x}/0x{offset:x}: {exc}"
            ) from None

    async def read_raw(self, port: int, group: int, offset: int, length: int) -> bytes:
        """Read ``length`` raw bytes at an ADS address."""
        return self._data(await self._call(ReadRequest, port, group, offset, length))

    async def read(self, name: str, units: bool = False) -> Any:
        """Read the object ``name``: its own value (0.1 um, 0.1 %, as the catalog says),
        or with ``units`` in engineering units (mm, %, rpm: ``ObjectInfo.scale``, its
        unit ``ObjectInfo.engineering_unit``), rounded to the object's resolution."""
        try:
            info = await self._object(name)
            reply = await self._call(ReadRequest, info.port, info.group, info.offset, info.length)
        except NoReplyError as exc:  # the first read of a name browses: name the READ
            raise exc.asking(f"READ {name}") from None
        value = _decode(info.dtype, self._payload(reply), info.name)
        return engineering(info, value) if units else value

    async def write_address(
        self, port: int, group: int, offset: int, dtype: DataType | str, value: Any
    ) -> None:
        """Write ``value`` encoded as ``dtype`` at an ADS address."""
        dtype = _coerce_type(dtype)
        data = _encode(dtype, value, f"0x{group:x}/0x{offset:x}")
        await self._call(WriteRequest, port, group, offset, data)

    async def read_write_raw(
        self, port: int, group: int, offset: int, data: bytes, read_length: int
    ) -> bytes:
        """ADS ReadWrite at an address: ``data`` in, up to ``read_length`` bytes out."""
        reply = await self._call(ReadWriteRequest, port, group, offset, read_length, data)
        return self._data(reply)

    async def write_raw(self, port: int, group: int, offset: int, data: bytes) -> None:
        """Write raw bytes at an ADS address."""
        await self._call(WriteRequest, port, group, offset, data)

    async def write(self, name: str, value: Any, units: bool = False) -> None:
        """Write the object ``name``; returns once the kernel has applied it. With
        ``units``, ``value`` is in engineering units (``write(override, 50, units=True)``
        writes 500 (0.1 %)). A value its type cannot hold raises ``ClientValueError``
        before anything is sent."""
        try:
            info = await self._object(name)
            if units:
                value = _raw(info, value)
            data = _encode(info.dtype, value, info.name)
            await self._call(WriteRequest, info.port, info.group, info.offset, data)
        except NoReplyError as exc:
            raise exc.asking(f"WRITE {name}") from None

    async def read_many(self, names: Iterable[str], units: bool = False) -> dict[str, Any]:
        """Read several objects in one sum-read round trip (handles cached per name);
        ``units`` as for ``read``."""
        names = list(names)
        try:
            values = await self._read_many(names)
        except NoReplyError as exc:
            shown = ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")
            raise exc.asking(f"READ {shown}") from None
        if units:
            return {n: engineering(await self._object(n), v) for n, v in values.items()}
        return values

    async def _read_many(self, names: list[str]) -> dict[str, Any]:
        infos = [await self._object(n) for n in names]
        missing = list(dict.fromkeys(i.name for i in infos if i.name not in self._handles))
        if missing:
            await self._acquire_handles(missing)
        items = [sums.SumItem(RIG.SYM_VALUE_BY_HANDLE, self._handles[i.name], i.length) for i in infos]
        data, read_length = sums.encode_sum_read(items)
        reply = await self._call(
            ReadWriteRequest, _HANDLE_PORT, RIG.SUM_READ, len(items), read_length, data
        )
        try:
            results = sums.decode_sum_read_reply([i.length for i in infos], self._payload(reply))
        except ValueError as exc:
            raise AdsError(AdsReturnCode.CLIENT_SYNCRESINVALID, str(exc)) from None
        values: dict[str, Any] = {}
        for info, (code, raw) in zip(infos, results):
            if code:
                raise AdsError(code, f"{info.name} (in a sum read)")
            values[info.name] = _decode(info.dtype, raw, info.name)
        return values

    async def _acquire_handles(self, names: list[str]) -> None:
        items = [
            sums.SumItem(RIG.SYM_HANDLE_BY_NAME, 0, 4, n.encode(STRING_ENCODING) + b"\x00")
            for n in names
        ]
        data, read_length = sums.encode_sum_read_write(items)
        reply = await self._call(
            ReadWriteRequest, _HANDLE_PORT, RIG.SUM_READ_WRITE, len(items), read_length, data
        )
        results = sums.decode_sum_read_write_reply(len(items), self._payload(reply))
        for name, (code, raw) in zip(names, results):
            if code:
                raise AdsError(code, f"handle of {name}")
            self._handles[name] = int.from_bytes(raw, "little")

    async def subscribe(
        self, name: str, on_change: bool = True, cycle_ms: int | None = None,
        units: bool = False, buffer_samples: int | None = SAMPLE_BUFFER,
    ) -> AsyncGenerator[Sample, None]:
        """Samples of ``name`` as the service sends them (server-side notification).

        ``on_change``: a sample when the value changed, checked every ``cycle_ms`` of kernel
        time (default 10 ms; 0: every kernel cycle, so that a value held for one cycle is
        seen); otherwise one every ``cycle_ms`` (default 100 ms). The first sample is the
        current value. Leaving the loop deletes the subscription. ``units``: the samples'
        values in engineering units, as for ``read``. ``buffer_samples``: how many samples
        wait for the loop at most (a loop that falls behind loses the oldest; the sample's
        ``sequence`` shows the gap); None keeps every one (a recorder of a repeatable
        trace, ``cnc_trace``: memory grows while the loop lags).
        """
        mode = TransmissionMode.SERVER_ON_CHANGE if on_change else TransmissionMode.SERVER_CYCLE
        default = DEFAULT_ON_CHANGE_CYCLE_MS if on_change else DEFAULT_CYCLIC_CYCLE_MS
        cycle = cycle_ms if cycle_ms is not None else default
        try:
            info = await self._object(name)
            reply = await self._call(
                AddNotificationRequest, info.port, info.group, info.offset, info.length,
                int(mode), 0, int(cycle),
            )
        except NoReplyError as exc:
            raise exc.asking(f"SUBSCRIBE {name}") from None
        handle = self._payload(reply)
        self._t.open_samples(handle, buffer_samples)
        try:
            while True:
                raw = await self._t.next_sample(handle)
                value = _decode(info.dtype, raw.data, info.name)
                yield Sample(
                    info.name,
                    engineering(info, value) if units else value,
                    filetime_to_datetime(raw.timestamp),
                    raw.sequence,
                )
        finally:
            self._t.close_samples(handle)
            with contextlib.suppress(AdsConnectionError):  # closed client: nothing to delete
                await self._call(DeleteNotificationRequest, info.port, handle)


def run_blocking(coro: Coroutine[Any, Any, T]) -> T:
    """Run one ``AsyncClient`` coroutine to completion on the blocking transport."""
    return drive(coro)


def iterate_blocking(agen: AsyncIterator[T]) -> Iterator[T]:
    """An ``AsyncClient`` async generator as a blocking iterator; leaving the loop closes
    the generator (a subscription is deleted)."""
    try:
        while True:
            try:
                # an async generator's step object has send() and throw(): a coroutine
                yield drive(cast("Coroutine[Any, Any, T]", agen.__anext__()))
            except StopAsyncIteration:
                return
    finally:
        aclose = getattr(agen, "aclose", None)
        if aclose is not None:
            drive(aclose())


class BlockingClientBase:
    """Connection handling of the blocking ``Client`` (``clients/blocking.py``, generated
    from ``AsyncClient``'s methods)."""

    def __init__(
        self,
        endpoint: str = DEFAULT_ENDPOINT,
        *,
        timeout_s: float = DEFAULT_TIMEOUT_S,
        key_file: PathText | None = None,
        server_key: PathText | None = None,
    ) -> None:
        """See ``AsyncClient`` (``key_file``, ``server_key``: CURVE keys)."""
        self.endpoint = endpoint
        curve = client_curve(key_file, server_key)
        self._core = AsyncClient(
            endpoint, _transport=SyncTransport(endpoint, timeout_s, curve=curve)
        )

    def __enter__(self) -> Self:
        drive(self._core._t.open())
        return self

    def __exit__(self, *exc: object) -> None:
        drive(self._core._t.close())


__all__ = [
    "AsyncClient", "BlockingClientBase", "ChannelStatus", "CheckError", "CheckResult", "DeviceInfo",
    "ObjectInfo", "ProgramEntry", "Sample", "filetime_to_datetime",
]
