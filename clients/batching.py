"""Batching of ``AsyncClient`` requests: the reads and the writes issued in one event-loop
turn (an ``asyncio.gather`` of 64 reads) go out as ADS sum commands, one frame for many.

Transparent to the caller: each request keeps its own future, answered with its own
``Response``, so results and errors are per request as before.

* A run of consecutive reads (or writes) to one AMS port becomes one sum read 0xF080
  (sum write 0xF081); nothing is reordered: a read between two writes cuts the run, and
  the items of a sum write are applied in their order, in one cycle. A run of one goes
  out as the plain request.
* A run is cut into sum commands of at most ``BATCH_MAX_ITEMS`` items and
  ``BATCH_MAX_BYTES`` of request and of reply data: below the smallest ``max_frame_bytes``
  a service may be configured with ([limits], 4096), so a batch is never refused for
  its size. A read or write of more than ``BATCH_ITEM_MAX_BYTES`` goes out alone, and so
  do requests to ADS's own index groups (0xF000..0xFFFF), the program store and the
  output area (their replies are not a value's bytes).
* A sum read slot that failed is asked again as the plain read (reads change nothing),
  so its error, or a string read at another length, is exactly what the plain read
  answers. A failed sum write slot is answered with its ADS code and the address (the
  sum reply carries codes only; asking again could apply it after later writes).
* A sum command the service refuses as a whole (a service without sum commands on this
  wire) changed nothing: its requests are sent again one by one.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable, Iterator
from typing import Any, Protocol

from cnc_objects.protocol import sum as sums
from cnc_objects.protocol.constants import (
    OUTPUT_AREA_GROUP,
    PROGRAM_STORE_GROUP,
    SUM_COMMAND_MAX_ITEMS,
    AdsCommand,
)
from cnc_objects.protocol.constants import ReservedIndexGroup as RIG
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.frames import Response

#: Request and reply data of one sum command at most: under the 4096-byte frame the
#: service may be limited to, with room for the frame's other fields.
BATCH_MAX_BYTES = 3072
BATCH_MAX_ITEMS = min(256, SUM_COMMAND_MAX_ITEMS)
#: A read or write larger than this goes out alone: batching saves frames, not bytes.
BATCH_ITEM_MAX_BYTES = 512

READ = int(AdsCommand.READ)
WRITE = int(AdsCommand.WRITE)
_ADS_SERVICE_GROUPS = range(0xF000, 0x10000)
_SERVICE_GROUPS = (PROGRAM_STORE_GROUP, OUTPUT_AREA_GROUP)
_SUM_GROUP = {READ: int(RIG.SUM_READ), WRITE: int(RIG.SUM_WRITE)}
_ITEM_HEAD_BYTES = 12  # group, offset, length of one sum item
_CODE_BYTES = 4  # one item's result code in a sum reply


class ReplyWaiter(Protocol):
    """What the transport keeps per invoke id: a future of the reply, or a ``SumBatch``."""

    def done(self) -> bool:
        """True when nobody waits for the reply any more."""
        ...

    def set_result(self, result: Response, /) -> None:
        """The reply arrived."""
        ...

    def set_exception(self, exception: BaseException, /) -> None:
        """No reply will come (timeout, closed)."""
        ...


def batchable(command: int, fields: tuple[Any, ...]) -> bool:
    """Whether a request may share a sum command: a Read or Write of an object's bytes."""
    if command == READ:
        size = fields[2]
    elif command == WRITE:
        size = len(fields[2])
    else:
        return False
    group = fields[0]
    return (size <= BATCH_ITEM_MAX_BYTES and group not in _ADS_SERVICE_GROUPS
            and group not in _SERVICE_GROUPS)


class QueuedRequest:
    """A Read or Write waiting in the outbox for the end of the loop turn."""

    __slots__ = ("fut", "command", "port", "fields")

    def __init__(self, fut: asyncio.Future[Response], command: int, port: int,
                 fields: tuple[Any, ...]) -> None:
        self.fut = fut
        self.command = command
        self.port = port
        self.fields = fields  # Read: (group, offset, length); Write: (group, offset, data)


def runs(outbox: list[Any]) -> Iterator[Any]:
    """The outbox in order, each maximal run of ``QueuedRequest`` of one command and port
    as a list, everything else (an already encoded frame) as it is."""
    run: list[QueuedRequest] = []
    for entry in outbox:
        if type(entry) is QueuedRequest:
            if run and (entry.command != run[0].command or entry.port != run[0].port):
                yield run
                run = []
            run.append(entry)
            continue
        if run:
            yield run
            run = []
        yield entry
    if run:
        yield run


def chunks(run: list[QueuedRequest]) -> list[list[QueuedRequest]]:
    """``run`` (one command) cut into sum commands within the item and byte limits."""
    # what each item adds to the request's data and to the reply's: a read its length to
    # the reply, a write its data to the request; each its head and its result code
    reads = run[0].command == READ
    sizes = [q.fields[2] if reads else len(q.fields[2]) for q in run]
    if len(run) <= BATCH_MAX_ITEMS and (
            _ITEM_HEAD_BYTES + _CODE_BYTES) * len(run) + sum(sizes) <= BATCH_MAX_BYTES:
        return [run]  # the common case: everything fits one
    out: list[list[QueuedRequest]] = []
    chunk: list[QueuedRequest] = []
    request_bytes = reply_bytes = 0
    for item, size in zip(run, sizes):
        more_request = _ITEM_HEAD_BYTES + (0 if reads else size)
        more_reply = _CODE_BYTES + (size if reads else 0)
        if chunk and (len(chunk) == BATCH_MAX_ITEMS
                      or request_bytes + more_request > BATCH_MAX_BYTES
                      or reply_bytes + more_reply > BATCH_MAX_BYTES):
            out.append(chunk)
            chunk, request_bytes, reply_bytes = [], 0, 0
        chunk.append(item)
        request_bytes += more_request
        reply_bytes += more_reply
    if chunk:
        out.append(chunk)
    return out


def sum_fields(chunk: list[QueuedRequest]) -> tuple[int, int, tuple[Any, ...]]:
    """The ReadWrite that carries ``chunk``: (command, port, fields)."""
    command = chunk[0].command
    if command == READ:
        data, read_length = sums.encode_sum_read_addresses([q.fields for q in chunk])
    else:
        data, read_length = sums.encode_sum_write(
            [sums.SumItem(q.fields[0], q.fields[1], 0, q.fields[2]) for q in chunk])
    return (int(AdsCommand.READ_WRITE), chunk[0].port,
            (_SUM_GROUP[command], len(chunk), read_length, data))


class SumBatch:
    """The reply waiter of one sum command: hands each item its own ``Response``.

    ``resend`` sends an item again as its plain request (a failed read slot, or every
    item of a sum command refused as a whole)."""

    __slots__ = ("items", "_resend")

    def __init__(self, items: list[QueuedRequest], resend: Callable[[QueuedRequest], None]) -> None:
        self.items = items
        self._resend = resend

    def done(self) -> bool:
        return all(item.fut.done() for item in self.items)

    def set_exception(self, exception: BaseException, /) -> None:
        for item in self.items:
            if not item.fut.done():
                item.fut.set_exception(exception)

    def set_result(self, result: Response, /) -> None:
        items = self.items
        if result.result:  # refused whole: nothing of it was applied
            for item in items:
                self._resend(item)
            return
        data = result.fields[0] if result.fields else b""
        try:
            if items[0].command == READ:
                self._answer_reads(data)
            else:
                self._answer_writes(data)
        except (ValueError, TypeError) as exc:
            self._answer_all(Response(0, items[0].command, AdsReturnCode.CLIENT_SYNCRESINVALID,
                                      (), f"unreadable sum reply: {exc}"))

    def _answer_reads(self, data: bytes) -> None:
        results = sums.decode_sum_read_reply([q.fields[2] for q in self.items], data)
        for item, (code, raw) in zip(self.items, results, strict=True):
            fut = item.fut
            if code:
                if not fut.done():
                    self._resend(item)  # the plain read's own answer: its sentence, or a string
            elif not fut.done():
                fut.set_result(Response(0, READ, 0, (raw,)))

    def _answer_writes(self, data: bytes) -> None:
        codes = sums.decode_codes(len(self.items), data)
        for item, code in zip(self.items, codes, strict=True):
            if item.fut.done():
                continue
            if code:
                group, offset = item.fields[0], item.fields[1]
                item.fut.set_result(Response(0, WRITE, code, (), (
                    f"write to port {item.port} 0x{group:x}/0x{offset:x} refused; it went out "
                    f"in a sum write of {len(self.items)}, whose reply carries only the code "
                    "(AsyncClient(batch=False) sends writes one by one, with the reason)")))
            else:
                item.fut.set_result(Response(0, WRITE, 0))

    def _answer_all(self, response: Response) -> None:
        for item in self.items:
            if not item.fut.done():
                item.fut.set_result(response)
