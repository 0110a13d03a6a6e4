"""Device notifications: subscriptions sampled in kernel time, sent on the event loop.

ADS semantics: SERVER_CYCLE sends the value every cycle time of kernel time;
SERVER_ON_CHANGE checks every cycle time and sends only when the bytes changed. Both
send the current value at once after the subscription is acknowledged; a sample is sent
in the pass that takes it, so the max delay a client asks for is always kept. Each
sample carries the handle, a per-subscription sequence number (a gap means a sample was
dropped because the client did not keep up; ADS frames leave it out) and a timestamp.

The timestamp is wall-clock time as a FILETIME: the instant the kernel cycle that
produced the value published its snapshot (``Snapshot.wall_ns``). Samples of one cycle
share it, and it never runs ahead of the wall clock, also not under the virtual clock
(where kernel time does): kernel time stays readable as ``cnc_kernel_time_r``. With
repeatable samples (``[clock] samples = "repeatable"``, docs/kernel.md "Traces that
repeat") it is the cycle's kernel time instead, and no sample is dropped.

The kernel thread only looks at one number per cycle (when the next sample is due) and
wakes the event loop when it is (the event-speed clock's bulk: once per ``WAKE_BATCH``
due cycles; a loop ``PASSES_PENDING_MAX`` due cycles behind holds it, issue 37
"Watched at 200x"); all sampling and sending happens on the loop, in
slices of at most ``SAMPLE_SLICE_S`` of loop time (``SamplingPass``): with the
notification limit used up by one client, another client's request waits one slice, not
a pass over every subscription.
A pass samples one cycle, the due one: the kernel keeps each due cycle's published
snapshot for its pass and runs on (issue 37: the event-speed clock runs in bulk to the
next due cycle meanwhile); every slice of the pass pins that snapshot
(``Kernel.reading``: every getter on the loop's thread sees it) and reads each address
once. A sample's data and timestamp thus come from the same cycle however
long a read takes and however many cycles the kernel publishes meanwhile; nothing is
read again. A slice looks at the clock by the bytes it read, not only by the
subscriptions it took, so a large subscription ends its slice (``SLICE_CHECK_BYTES``).
A subscription to one object's whole value reads it the short way (``sample_reads``:
the object's getter and encoder, resolved once; issue 37), every other one through the
read dispatcher.

What one subscription may cost is bounded by ``NotificationLimits`` (``[limits]``): the
bytes one notification carries (``notification_max_bytes``) and the bytes of all
notifications one client holds (``notification_bytes_per_client``); beyond either,
AddDeviceNotification is answered 0x717 (ADSERR_DEVICE_INVALIDWATCHSIZE, TwinCAT's
"notification size too large") and nothing is subscribed.

One hub serves every front end: a subscription remembers the front end's ``notify``
function, which turns samples into that front end's frames (msgpack for ZeroMQ, a
DeviceNotification for ADS over AMS/TCP). The limits (``[limits]
notifications_per_client`` and ``notifications_total``) count both front ends together;
``counts`` (served as the objects ``cnc_notifications_r`` and
``cnc_notification_clients_r``) says how many are open and for how many clients, so a
test can watch a vanished client's notifications being freed.
"""

from __future__ import annotations

import asyncio
import logging
import threading
from collections import deque
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager
from dataclasses import dataclass, field
from time import perf_counter
from typing import Any

from cnc_objects.protocol.constants import TransmissionMode
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.filetime import filetime_from_unix_ns

from .kernel.state import Snapshot
from .sample_reads import FAILED, Probe, Probes, ResolveFn, unchanged

log = logging.getLogger(__name__)

ReadFn = Callable[[int, int, int, int], tuple[int, bytes | str]]
#: Where a front end sends to: its own address of one client (hashable, compared by value).
Envelope = tuple[Any, ...]
SendFn = Callable[[Envelope, bytes], bool]
#: A front end's sender of samples: (envelope, port, [[handle, sequence, FILETIME, data],
#: ...]) -> delivered. It encodes them in its own wire format.
NotifyFn = Callable[[Envelope, int, list[list[Any]]], bool]

CYCLIC_MODES = {TransmissionMode.SERVER_CYCLE, TransmissionMode.SERVER_CYCLE2}
ON_CHANGE_MODES = {TransmissionMode.SERVER_ON_CHANGE, TransmissionMode.SERVER_ON_CHANGE2}
#: Pins a snapshot (None: the kernel's newest) for the calling thread while the block
#: lasts (``Kernel.reading``); yields it.
PinFn = Callable[[Snapshot | None], AbstractContextManager[Snapshot]]
#: Reads of one sampling pass by (port, group, offset, length).
_Reads = dict[tuple[int, int, int, int], tuple[int, bytes | str]]

MAX_PER_CLIENT = 1000  # default of [limits] notifications_per_client
MAX_TOTAL = 20000  # default of [limits] notifications_total
#: The length of an AddDeviceNotification that does not know the value's size (ads-client
#: sends it by handle): the value's own size is taken.
UNKNOWN_LENGTH = 0xFFFF_FFFF
#: Default of [limits] notification_max_bytes: the largest symbol of the PLC memory
#: area (gpCh, both channels' HLI structs) may be watched whole.
MAX_BYTES = 8 << 10
#: Default of [limits] notification_bytes_per_client: eight times ``MAX_BYTES``, or
#: 1000 notifications (the per-client count) of 64 bytes each.
MAX_BYTES_PER_CLIENT = 64 << 10
#: Loop time one slice of a sampling pass may take before requests go first. Another
#: client's read waits at most about this long (plus one read) behind the notifications
#: of all clients.
SAMPLE_SLICE_S = 0.0005
SLICE_CHECK_EVERY = 32  # subscriptions sampled between two looks at the clock
#: Bytes read between two looks at the clock: a read's cost grows with its length (a
#: range of the PLC memory area reads every symbol in it), so a few large subscriptions
#: end a slice as many small ones do.
SLICE_CHECK_BYTES = 2048
#: Due cycles the kernel keeps for passes not yet begun. While this many wait, the
#: event-speed clock waits until the loop has sampled all but ``PASSES_PENDING_LOW`` of
#: them (the loop is behind: a pass costs more than the cruising cycles between two due
#: ones); with repeatable samples every clock's cycle thread waits until there is room
#: for one (the loop may wait for a slow reader: the kernel goes on as soon as it can).
#: Under the other clocks with latest samples (the realtime clock never waits) a due
#: cycle beyond it pushes out the oldest waiting one (the newest values go out, none
#: older).
PASSES_PENDING_MAX = 64
#: Due cycles left waiting when the loop wakes a cycle thread that waits for room: it then
#: runs several due cycles before it waits again, instead of one per pass the loop ends
#: (each wake-up hands the GIL over twice; issue 37, docs/kernel.md "Watched at 200x").
PASSES_PENDING_LOW = 16
#: Due cycles the event-speed bulk keeps before it wakes the loop (latest samples): one
#: wake-up, and its two hand-overs of the GIL, for a batch of passes instead of one each
#: (issue 37, docs/kernel.md "Watched at 200x"). A batch is a few bulk steps: well under
#: a millisecond of wall time.
WAKE_BATCH = 16
#: Repeatable samples: how often the loop tries again to send the frames a client's
#: full send queue refused (no front end says per client when it has room again).
BACKLOG_RETRY_S = 0.001
#: Repeatable samples: how long the cycle thread waits for room at a time before it
#: looks again whether the hub was closed.
ROOM_WAIT_S = 0.1


@dataclass(frozen=True, slots=True)
class NotificationLimits:
    """What the notifications of one client and of all clients may hold (``[limits]``
    notifications_per_client, notifications_total: 0x716 beyond; notification_max_bytes,
    notification_bytes_per_client: 0x717 beyond)."""

    per_client: int = MAX_PER_CLIENT
    total: int = MAX_TOTAL
    max_bytes: int = MAX_BYTES
    bytes_per_client: int = MAX_BYTES_PER_CLIENT


@dataclass(slots=True)
class NotificationCounts:
    """Open notifications of all clients, and the clients that hold any (read by the
    address space on the event loop, written by the hub on it)."""

    total: int = 0
    clients: int = 0


@dataclass(slots=True)
class Subscription:
    """One client's subscription to one address."""

    handle: int
    envelope: Envelope
    notify: NotifyFn
    port: int
    group: int
    offset: int
    length: int
    on_change: bool
    cycle_ns: int
    next_due_ns: int
    last: bytes | None = None
    sequence: int = 0
    #: reads the object the short way (``sample_reads``); None: through the dispatcher
    probe: Probe | None = None
    last_value: Any = FAILED  # the value ``last`` was encoded from (a probe's)
    batch_key: tuple[Envelope, int] = ((), 0)  # (envelope, port): its frame in a slice

    def __post_init__(self) -> None:
        self.batch_key = (self.envelope, self.port)


@dataclass(slots=True)
class SamplingPass:
    """One pass over the subscriptions, done in slices of loop time: the kernel time it
    samples for, the snapshot every slice reads (that due cycle's, kept by the kernel),
    the subscriptions still to look at, and the reads so far by address (every address
    is read once per pass)."""

    now_ns: int
    snapshot: Snapshot
    todo: Iterator[Subscription]
    reads: _Reads = field(default_factory=dict)


#: Due time of a subscription whose first sample has not gone out yet: the cycle's sampling
#: leaves it alone (else an unchanged value would go out twice, from both).
FIRST_SAMPLE_PENDING = 1 << 63


class NotificationHub:
    """All subscriptions of the server."""

    def __init__(
        self,
        read: ReadFn,
        loop: asyncio.AbstractEventLoop,
        kernel_cycle_ns: int,
        pin: PinFn,
        limits: NotificationLimits | None = None,
        counts: NotificationCounts | None = None,
        repeatable: bool = False,
        resolve: ResolveFn | None = None,
    ) -> None:
        """``read`` serves an address on the loop, from the snapshot the kernel shows
        the calling thread; ``pin`` pins a snapshot for a block (``Kernel.reading``);
        ``resolve`` gives the getter and encoder of an address that is one object's whole
        value, which the passes then read the short way (``sample_reads``).
        ``repeatable`` (``[clock] samples = "repeatable"``): no sample is ever dropped.
        The cycle thread waits while ``PASSES_PENDING_MAX`` due cycles wait for their
        passes; a frame a client's send queue refuses is kept and sent again, and no
        pass begins until it went out (so a slow reader holds the passes, and the
        passes the kernel); the first sample is taken when the subscription is added;
        samples carry kernel time, not wall time (docs/kernel.md, Traces that repeat)."""
        self._read = read
        self._probes = Probes(resolve)
        self._read_no = 0  # counts the passes and first samples: a probe reads once in each
        self._pin = pin
        self._loop = loop
        self._kernel_cycle_ns = kernel_cycle_ns
        self._subs: dict[int, Subscription] = {}
        # Open notifications by client: by connection (an envelope's first part, ZeroMQ's
        # routing id or the ADS connection), so that the parts a client adds to its
        # envelope do not make it several clients.
        self._per_client: dict[Any, int] = {}
        self._bytes_per_client: dict[Any, int] = {}  # their lengths summed, by connection
        # Subscriptions by envelope, with the front end's notify: ``clients`` without a
        # look at every subscription (the ZeroMQ probe asks every 2 s).
        self._envelopes: dict[Envelope, tuple[NotifyFn, int]] = {}
        self.limits = limits if limits is not None else NotificationLimits()
        self.counts = counts if counts is not None else NotificationCounts()
        self._next_handle = 1
        # The due grid, shared with the cycle thread: every due time is a multiple of a
        # subscription's cycle_ns. The loop replaces the tuple (never changes it) when a
        # cycle time comes or goes; ``_period_counts`` counts subscriptions per cycle time.
        self._periods: tuple[int, ...] = ()
        self._period_counts: dict[int, int] = {}
        # cycle thread only: the kernel time of the next due cycle, the grid it was taken
        # from, and the last cycle seen
        self._kernel_due_ns: int | None = None
        # the due time the event-speed bulk runs to (``next_observed_ns``), and whether
        # due cycles it ran to wait without the loop woken (``kernel_cycle_end``)
        self._bulk_due_ns: int | None = None
        self._deferred = False
        self._due_from: tuple[int, ...] = ()
        self._seen_ns = 0
        # Due cycles' snapshots the passes still have to sample, oldest first (the kernel
        # appends, the loop takes), and whether a pass is scheduled or under way: both
        # under ``_handover``.
        self.repeatable = repeatable
        self._due_snapshots: deque[Snapshot] = deque(
            maxlen=None if repeatable else PASSES_PENDING_MAX)
        self._handover = threading.Condition()  # a cycle thread that waits for room waits on it
        # (under ``_handover``) the due cycles a cycle thread that waits for room waits
        # for the loop to get down to; -1: none waits
        self._room_left = -1
        self._closed = False  # ``close``: the cycle thread waits no more
        self._scheduled = False
        # Repeatable samples: frames a client's send queue refused, in order, with the
        # timer that tries them again (latest samples: always empty).
        self._backlog: deque[tuple[Envelope, int, NotifyFn, list[list[Any]]]] = deque()
        self._retry: asyncio.TimerHandle | None = None
        self._pass: SamplingPass | None = None  # the sampling pass in progress
        self._stamp = 0  # FILETIME of the snapshot pinned while sampling
        self._read_bytes = 0  # bytes the slice under way has read (not shared)
        self.dropped = 0

    def __len__(self) -> int:
        return len(self._subs)

    # ------------------------------------------------------------ requests

    def add(
        self, envelope: Envelope, req: Any, cycle_ns: int, notify: NotifyFn,
        first_delay_s: float = 0.0,
    ) -> tuple[int, int | str]:
        """Subscribe ``envelope`` to ``req`` (port, group, offset, length and
        transmission_mode of an AddDeviceNotification), checked every ``cycle_ns`` of
        kernel time (at least every kernel cycle); (0, handle) or (code, message). The
        first sample follows the reply through ``notify``, ``first_delay_s`` of wall
        time after it."""
        mode = req.transmission_mode
        if mode not in CYCLIC_MODES and mode not in ON_CHANGE_MODES:
            return (
                AdsReturnCode.DEVICE_TRANSMODENOTSUPP,
                f"transmission mode {mode} is not a server mode (use 3 cyclic or 4 on change)",
            )
        if req.length != UNKNOWN_LENGTH:  # refused before anything is read
            refused = self._size_refusal(envelope, req.length)
            if refused is not None:
                return refused
        code, data = self._read(req.port, req.group, req.offset, req.length)
        if code:
            return code, data  # type: ignore[return-value]
        # "I do not know the size" (0xFFFFFFFF, by handle): the value's own size, which
        # the limits count and every pass reads
        length = len(data) if req.length == UNKNOWN_LENGTH else req.length
        if req.length == UNKNOWN_LENGTH:
            refused = self._size_refusal(envelope, length)
            if refused is not None:
                return refused
        limits = self.limits
        mine = self._per_client.get(envelope[0], 0)
        if mine >= limits.per_client:
            return (AdsReturnCode.DEVICE_NOMOREHDLS,
                    f"this client holds {mine} notifications, the most one client may "
                    "([limits] notifications_per_client); delete some first")
        if len(self._subs) >= limits.total:
            return (AdsReturnCode.DEVICE_NOMOREHDLS,
                    f"the service holds {len(self._subs)} notifications, the most it takes "
                    "([limits] notifications_total); delete some first")
        handle = self._next_handle
        self._next_handle += 1
        sub = Subscription(
            handle, envelope, notify, req.port, req.group, req.offset, length,
            mode in ON_CHANGE_MODES, max(cycle_ns, self._kernel_cycle_ns), FIRST_SAMPLE_PENDING,
            probe=self._probes.probe(req.port, req.group, req.offset, length),
        )
        self._subs[handle] = sub
        self._count_period(sub.cycle_ns, 1)
        self._per_client[envelope[0]] = mine + 1
        key = envelope[0]
        self._bytes_per_client[key] = self._bytes_per_client.get(key, 0) + length
        held = self._envelopes.get(envelope)
        self._envelopes[envelope] = (notify, 1 if held is None else held[1] + 1)
        self._count()
        # repeatable: the first sample is the cycle the subscription was added at, not
        # whatever cycle the kernel has reached when the loop sends it
        first = self._take_first(sub) if self.repeatable else None
        if first_delay_s > 0:
            self._loop.call_later(first_delay_s, self._first_sample, sub, first)
        else:
            self._loop.call_soon(self._first_sample, sub, first)
        return 0, handle

    def _size_refusal(self, envelope: Envelope, length: int) -> tuple[int, str] | None:
        """0x717 and why, when a notification of ``length`` bytes is more than one may
        carry or than this client may still hold; None when it fits."""
        limits = self.limits
        if length > limits.max_bytes:
            return (AdsReturnCode.DEVICE_INVALIDWATCHSIZE,
                    f"a notification of {length} bytes is larger than one may be "
                    f"({limits.max_bytes} bytes, [limits] notification_max_bytes); "
                    "subscribe to the parts you need")
        held = self._bytes_per_client.get(envelope[0], 0)
        if held + length > limits.bytes_per_client:
            return (AdsReturnCode.DEVICE_INVALIDWATCHSIZE,
                    f"this client's notifications hold {held} bytes; {length} more exceed "
                    f"the {limits.bytes_per_client} one client may hold ([limits] "
                    "notification_bytes_per_client); delete some first")
        return None

    def delete(self, envelope: Envelope, handle: int) -> tuple[int, str]:
        """End a subscription of this client; 0x714 when it has no such handle."""
        sub = self._subs.get(handle)
        if sub is None or sub.envelope != envelope:
            return AdsReturnCode.DEVICE_NOTIFYHNDINVALID, f"notification handle {handle} is unknown"
        del self._subs[handle]
        self._forget_one(sub)
        self._count()
        return 0, ""

    def drop_client(self, envelope: Envelope) -> None:
        """Forget every subscription of a client that is gone."""
        if envelope[0] not in self._per_client:
            return
        gone = [s for s in self._subs.values() if s.envelope == envelope]
        for sub in gone:
            del self._subs[sub.handle]
            self._forget_one(sub)
        if not gone:
            return
        self._count()
        log.info("client gone: dropped %d notifications", len(gone))

    def clients(self) -> list[tuple[Envelope, NotifyFn]]:
        """Every client that holds notifications, with the ``notify`` of its front end."""
        return [(envelope, notify) for envelope, (notify, _) in self._envelopes.items()]

    def _count_period(self, cycle_ns: int, change: int) -> None:
        """Count a subscription of ``cycle_ns`` in (1) or out (-1) of the due grid; the
        grid the cycle thread reads is replaced when a cycle time comes or goes."""
        counts = self._period_counts
        held = counts.get(cycle_ns, 0) + change
        if held:
            counts[cycle_ns] = held
        else:
            del counts[cycle_ns]
        if held in (0, 1) and (held == 0 or change > 0):
            self._periods = tuple(sorted(counts))

    def _forget_one(self, sub: Subscription) -> None:
        self._count_period(sub.cycle_ns, -1)
        envelope = sub.envelope
        notify, count = self._envelopes[envelope]
        if count > 1:
            self._envelopes[envelope] = (notify, count - 1)
        else:
            del self._envelopes[envelope]
        key = envelope[0]
        left = self._per_client[key] - 1
        if left:
            self._per_client[key] = left
            self._bytes_per_client[key] -= sub.length
        else:
            del self._per_client[key]
            del self._bytes_per_client[key]

    def _count(self) -> None:
        self.counts.total = len(self._subs)
        self.counts.clients = len(self._per_client)

    # ------------------------------------------------------------ sampling

    def kernel_cycle_end(self, snapshot: Snapshot) -> None:
        """Called by the cycle thread after each published cycle: keep a due cycle's
        snapshot for its pass and wake the loop (once, while no pass is scheduled). The
        kernel goes on at once: the pass reads the snapshot kept, whatever the kernel
        has run meanwhile.

        A due cycle the event-speed clock's bulk ran to (the one ``next_observed_ns``
        named) wakes the loop only when ``WAKE_BATCH`` due cycles wait (latest samples):
        the bulk goes on to the next one at once, and the loop then samples the batch in
        one go. Any other published cycle (an event's, a cycle at rest, every cycle of
        the other clocks) wakes it for what waits, so a kept due cycle waits for its
        pass only while the kernel runs in bulk (issue 37, docs/kernel.md "Watched at
        200x")."""
        now_ns = self._seen_ns = snapshot.time_ns
        in_bulk = now_ns == self._bulk_due_ns
        self._bulk_due_ns = None
        due = self._kernel_due()
        if due is None or now_ns < due:
            if self._deferred:
                self._wake()
            return
        self._kernel_due_ns = _after(now_ns, self._due_from)
        with self._handover:
            if self.repeatable:  # nothing is pushed out: wait for the loop to make room
                self._wait_for_room(PASSES_PENDING_MAX - 1)
            self._due_snapshots.append(snapshot)
            if self._scheduled:
                return
            if (in_bulk and not self.repeatable and snapshot.stats.running
                    and len(self._due_snapshots) < WAKE_BATCH):
                self._deferred = True
                return
            self._scheduled = True
            self._deferred = False
        self._loop.call_soon_threadsafe(self._sample)

    def _wake(self) -> None:
        """(cycle thread) Wake the loop for the due cycles a bulk kept without waking it."""
        with self._handover:
            self._deferred = False
            if self._scheduled or not self._due_snapshots:
                return
            self._scheduled = True
        self._loop.call_soon_threadsafe(self._sample)

    def next_observed_ns(self) -> int | None:
        """Kernel time of the next cycle ``kernel_cycle_end`` must see (None: none): the
        event-speed virtual clock runs the cycles before it in bulk, unpublished, also
        while passes are pending (each reads the snapshot of its own due cycle). Every
        subscription's due times lie on the grid of its cycle time, so the next due
        cycle is the grid's next point. Only the event-speed clock asks (before each
        bulk): when ``PASSES_PENDING_MAX`` due cycles wait for the loop, the cycle thread
        waits here until the loop has sampled all but ``PASSES_PENDING_LOW`` of them.
        Stepping single cycles meanwhile (as before issue 37's "Watched at 200x") cost
        more than the passes it waited for (the kernel thread and the loop share one
        GIL) and pushed the oldest kept due cycles out: samples were lost for nothing
        but CPU. A client does not hold the kernel by this (with latest samples the
        passes never wait for a client's socket). With repeatable samples the cycle
        thread waits for room in ``kernel_cycle_end``."""
        if len(self._due_snapshots) >= PASSES_PENDING_MAX and not self.repeatable:
            with self._handover:
                self._wait_for_room(PASSES_PENDING_LOW)
        due = self._bulk_due_ns = self._kernel_due()  # ``kernel_cycle_end``: in bulk
        return due

    def _wait_for_room(self, left: int) -> None:
        """(cycle thread, under ``_handover``) When ``PASSES_PENDING_MAX`` due cycles
        wait, wait until the loop has taken all but ``left`` of them (or the hub is
        closed)."""
        if len(self._due_snapshots) < PASSES_PENDING_MAX:
            return
        self._room_left = left
        try:
            while len(self._due_snapshots) > left and not self._closed:
                self._handover.wait(ROOM_WAIT_S)
        finally:
            self._room_left = -1

    def _kernel_due(self) -> int | None:
        """(cycle thread) The next due kernel time on the current grid."""
        periods = self._periods
        if periods is not self._due_from:  # a cycle time came or went: a new grid
            self._due_from = periods
            self._kernel_due_ns = _after(self._seen_ns, periods)
        return self._kernel_due_ns

    def _take_first(self, sub: Subscription) -> list[Any]:
        """The first sample of ``sub``: its value in the kernel's newest cycle."""
        self._read_no += 1
        with self._pin(None) as pinned:
            self._stamp = self._filetime(pinned)
            sample = self._take(sub, pinned.time_ns, None, force=True)
        assert sample is not None  # forced: a sample whether or not the value changed
        return sample

    def _first_sample(self, sub: Subscription, sample: list[Any] | None) -> None:
        if sub.handle not in self._subs:
            return
        if sample is None:
            sample = self._take_first(sub)
        self._emit({(sub.envelope, sub.port): (sub.notify, [sample])})

    def _sample(self) -> None:
        """Begin a sampling pass over every subscription for the oldest due cycle the
        kernel kept; when none is left, the next due cycle schedules the next pass.
        While frames wait in the backlog (repeatable samples) no pass begins: the retry
        comes back here once they went out."""
        if self._backlog or self._pass is not None:
            return
        if self._next_pass():
            self._continue_pass()

    def _next_pass(self) -> bool:
        """Begin the pass of the oldest due cycle kept; False (and none scheduled) when
        none is left."""
        with self._handover:
            if not self._due_snapshots:
                self._scheduled = False
                return False
            snapshot = self._due_snapshots.popleft()
            if len(self._due_snapshots) == self._room_left:
                self._handover.notify()  # the cycle thread that waits for room goes on
        self._read_no += 1
        self._pass = SamplingPass(snapshot.time_ns, snapshot, iter(list(self._subs.values())))
        return True

    def _continue_pass(self) -> None:
        """Sample for at most ``SAMPLE_SLICE_S`` of loop time, send what was taken, and
        come back after the loop has served what waits (requests of other clients go
        between two slices, however many subscriptions there are). Every pass reads its
        due cycle's snapshot and each address once. The passes of further due cycles
        kept go on in the same slice: their samples share the slice's frames (each with
        its own cycle's timestamp), one frame per client, not one per cycle."""
        batches: dict[tuple[Envelope, int], tuple[NotifyFn, list[list[Any]]]] = {}
        deadline_s = perf_counter() + SAMPLE_SLICE_S
        while True:
            if not self._slice(batches, deadline_s):
                self._emit(batches)
                if not self._backlog:  # else the retry goes on once the backlog went out
                    self._loop.call_soon(self._continue_pass)
                return
            self._pass = None
            if perf_counter() > deadline_s:
                self._emit(batches)
                self._loop.call_soon(self._sample)  # the next due cycle kept, if any
                return
            if not self._next_pass():
                self._emit(batches)
                return

    def _slice(self, batches: dict[tuple[Envelope, int], tuple[NotifyFn, list[list[Any]]]],
               deadline_s: float) -> bool:
        """Go on with the pass under way until ``deadline_s``, adding its samples to
        ``batches``; True when the pass is done."""
        run = self._pass
        assert run is not None
        subs, take, due_ns, reads = self._subs, self._take, run.now_ns, run.reads
        read_no = self._read_no
        finished = True
        self._read_bytes = 0  # read since the last look at the clock
        with self._pin(run.snapshot) as pinned:
            # every sample of the pass carries its cycle's FILETIME
            self._stamp, now_ns = self._filetime(pinned), pinned.time_ns
            for k, sub in enumerate(run.todo, 1):
                if subs.get(sub.handle) is not sub:
                    continue  # deleted since the pass began
                if sub.next_due_ns <= due_ns:
                    probe = sub.probe
                    if probe is None or not sub.on_change:
                        sample = take(sub, now_ns, reads, False)
                    else:
                        # The common case of a page that watches many values, without
                        # a call: an on-change value that stands still (as ``_take``
                        # and ``Probe.value_in`` would find it).
                        if probe.read_no != read_no:
                            probe.read_no, probe.data = read_no, None
                            try:
                                probe.value = probe.getter()
                            except Exception:  # the dispatcher's read says why
                                probe.value = FAILED
                        value, last = probe.value, sub.last_value
                        if value is not FAILED and (value is last or unchanged(value, last)):
                            sample = None
                            cycle_ns = sub.cycle_ns  # the next due time, as ``_take`` sets it
                            sub.next_due_ns = now_ns - now_ns % cycle_ns + cycle_ns
                        else:
                            sample = take(sub, now_ns, reads, False)
                    if sample is not None:
                        batch = batches.get(sub.batch_key)
                        if batch is None:
                            batch = batches[sub.batch_key] = (sub.notify, [])
                        batch[1].append(sample)
                if k % SLICE_CHECK_EVERY and self._read_bytes < SLICE_CHECK_BYTES:
                    continue
                self._read_bytes = 0
                if perf_counter() > deadline_s:
                    finished = False
                    break
        return finished

    def _filetime(self, pinned: Snapshot) -> int:
        """The FILETIME the samples of the pinned cycle carry: its wall time, or with
        repeatable samples its kernel time (so that a trace repeats)."""
        return filetime_from_unix_ns(pinned.time_ns if self.repeatable else pinned.wall_ns)

    def _take(self, sub: Subscription, now_ns: int, reads: _Reads | None,
              force: bool) -> list[Any] | None:
        """Read one subscription in the pinned snapshot of kernel time ``now_ns`` (once
        per address in ``reads``, when given); a sample list or None when on-change saw
        no change. An on-change subscription with a probe compares the value first and
        encodes only one that may have changed (``sample_reads.unchanged``)."""
        # Next due time on the subscription's own grid, never in the past.
        cycle_ns = sub.cycle_ns
        sub.next_due_ns = now_ns - now_ns % cycle_ns + cycle_ns
        compare = sub.on_change and not force
        probe = sub.probe
        data: bytes | str | None = None
        if probe is not None:
            read_no = self._read_no
            value = probe.value if probe.read_no == read_no else probe.value_in(read_no)
            if value is not FAILED:
                if compare:
                    last = sub.last_value
                    if value is last or unchanged(value, last):  # the same object: unchanged
                        return None
                data = probe.encoded()
                sub.last_value = value if data is not None else FAILED
        if data is None:  # no probe, or its read failed: the dispatcher reads (and says why)
            code, data = self._read_shared(reads, sub.port, sub.group, sub.offset, sub.length)
            if code:
                return None  # the object went away (cannot happen with a fixed catalog)
        if compare and data == sub.last:
            return None
        sub.last = data  # type: ignore[assignment]
        sub.sequence += 1
        return [sub.handle, sub.sequence, self._stamp, data]

    def _read_shared(self, reads: _Reads | None, port: int, group: int, offset: int,
                     length: int) -> tuple[int, bytes | str]:
        """(code, data) of an address in the pinned snapshot, read once per pass: the
        subscriptions of one object share one read (a client may open thousands on
        the same object). Values outside the snapshot (counts, alarms) are as the
        pass's first read found them: the next pass reads them again."""
        if reads is None:
            return self._read(port, group, offset, length)
        key = (port, group, offset, length)
        hit = reads.get(key)
        if hit is None:
            hit = reads[key] = self._read(port, group, offset, length)
            self._read_bytes += length
        return hit

    def _emit(self, batches: dict[tuple[Envelope, int], tuple[NotifyFn, list[list[Any]]]]) -> None:
        """One frame per client and port with all its samples of this cycle. With
        repeatable samples a frame that is not delivered waits in the backlog, and so do
        all after it, until the retry sends them."""
        backlog = self._backlog
        for (envelope, port), (notify, samples) in batches.items():
            samples = [s for s in samples if s is not None]
            if not samples:
                continue
            if backlog:  # repeatable: behind the frames that wait, in order
                backlog.append((envelope, port, notify, samples))
            elif not notify(envelope, port, samples):
                if self.repeatable:
                    backlog.append((envelope, port, notify, samples))
                    self._retry_later()
                else:
                    self.dropped += len(samples)

    def _retry_later(self) -> None:
        if self._retry is None and not self._closed:
            self._retry = self._loop.call_later(BACKLOG_RETRY_S, self._send_backlog)

    def _send_backlog(self) -> None:
        """Send the frames that wait, oldest first, until one is refused again (then try
        later); when all went out, the passes go on where they stopped. Frames of a
        client that is gone are forgotten."""
        self._retry = None
        backlog = self._backlog
        while backlog:
            envelope, port, notify, samples = backlog[0]
            if envelope in self._envelopes and not notify(envelope, port, samples):
                if envelope in self._envelopes:  # refused, not gone: later
                    self._retry_later()
                    return
            backlog.popleft()
        if self._pass is not None:
            self._continue_pass()
        else:
            self._sample()

    def close(self) -> None:
        """The service stops: a cycle thread that waits for room goes on, and nothing is
        tried again."""
        with self._handover:
            self._closed = True
            self._handover.notify_all()
        if self._retry is not None:
            self._retry.cancel()
            self._retry = None



def _after(now_ns: int, periods: tuple[int, ...]) -> int | None:
    """The first kernel time after ``now_ns`` on the grid of ``periods`` (None: empty)."""
    return min((now_ns - now_ns % p + p for p in periods), default=None)
