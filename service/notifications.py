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
(where kernel time does): kernel time stays readable as ``cnc_kernel_time_r``.

The kernel thread only looks at one number per cycle (when the next sample is due) and
wakes the event loop when it is; all sampling and sending happens on the loop.

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
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from cnc_objects.protocol.constants import TransmissionMode
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.filetime import filetime_from_unix_ns

from .kernel.state import Snapshot

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
MAX_PER_CLIENT = 1000  # default of [limits] notifications_per_client
MAX_TOTAL = 20000  # default of [limits] notifications_total

#: FILETIME (100 ns since 1601-01-01) of the Unix epoch.


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
        current: Callable[[], Snapshot],
        max_per_client: int = MAX_PER_CLIENT,
        max_total: int = MAX_TOTAL,
        counts: NotificationCounts | None = None,
    ) -> None:
        self._read = read
        self._current = current
        self._loop = loop
        self._kernel_cycle_ns = kernel_cycle_ns
        self._subs: dict[int, Subscription] = {}
        # Open notifications by client: by connection (an envelope's first part, ZeroMQ's
        # routing id or the ADS connection), so that the parts a client adds to its
        # envelope do not make it several clients.
        self._per_client: dict[Any, int] = {}
        self.max_per_client = max_per_client
        self.max_total = max_total
        self.counts = counts if counts is not None else NotificationCounts()
        self._next_handle = 1
        self._next_due_ns: int | None = None
        self._scheduled = False
        self._last_snapshot: Snapshot | None = None
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
        code, data = self._read(req.port, req.group, req.offset, req.length)
        if code:
            return code, data  # type: ignore[return-value]
        mine = self._per_client.get(envelope[0], 0)
        if mine >= self.max_per_client:
            return (AdsReturnCode.DEVICE_NOMOREHDLS,
                    f"this client holds {mine} notifications, the most one client may "
                    "([limits] notifications_per_client); delete some first")
        if len(self._subs) >= self.max_total:
            return (AdsReturnCode.DEVICE_NOMOREHDLS,
                    f"the service holds {len(self._subs)} notifications, the most it takes "
                    "([limits] notifications_total); delete some first")
        handle = self._next_handle
        self._next_handle += 1
        sub = Subscription(
            handle, envelope, notify, req.port, req.group, req.offset, req.length,
            mode in ON_CHANGE_MODES, max(cycle_ns, self._kernel_cycle_ns), FIRST_SAMPLE_PENDING,
        )
        self._subs[handle] = sub
        self._per_client[envelope[0]] = mine + 1
        self._count()
        if first_delay_s > 0:
            self._loop.call_later(first_delay_s, self._first_sample, sub)
        else:
            self._loop.call_soon(self._first_sample, sub)
        return 0, handle

    def delete(self, envelope: Envelope, handle: int) -> tuple[int, str]:
        """End a subscription of this client; 0x714 when it has no such handle."""
        sub = self._subs.get(handle)
        if sub is None or sub.envelope != envelope:
            return AdsReturnCode.DEVICE_NOTIFYHNDINVALID, f"notification handle {handle} is unknown"
        del self._subs[handle]
        self._forget_one(envelope)
        self._count()
        self._update_due()
        return 0, ""

    def drop_client(self, envelope: Envelope) -> None:
        """Forget every subscription of a client that is gone."""
        if envelope[0] not in self._per_client:
            return
        gone = [h for h, s in self._subs.items() if s.envelope == envelope]
        for handle in gone:
            del self._subs[handle]
            self._forget_one(envelope)
        if not gone:
            return
        self._count()
        log.info("client gone: dropped %d notifications", len(gone))
        self._update_due()

    def clients(self) -> list[tuple[Envelope, NotifyFn]]:
        """Every client that holds notifications, with the ``notify`` of its front end."""
        seen: dict[Envelope, NotifyFn] = {}
        for sub in self._subs.values():
            seen.setdefault(sub.envelope, sub.notify)
        return list(seen.items())

    def _forget_one(self, envelope: Envelope) -> None:
        key = envelope[0]
        left = self._per_client[key] - 1
        if left:
            self._per_client[key] = left
        else:
            del self._per_client[key]

    def _count(self) -> None:
        self.counts.total = len(self._subs)
        self.counts.clients = len(self._per_client)

    # ------------------------------------------------------------ sampling

    def kernel_cycle_end(self, snapshot: Snapshot) -> None:
        """Called by the cycle thread after each cycle: wake the loop when a sample is due."""
        due = self._next_due_ns
        if due is not None and snapshot.time_ns >= due and not self._scheduled:
            self._scheduled = True
            self._last_snapshot = snapshot
            self._loop.call_soon_threadsafe(self._sample)

    def _first_sample(self, sub: Subscription) -> None:
        if sub.handle not in self._subs:
            return
        self._emit({(sub.envelope, sub.port): (sub.notify, [self._take(sub, force=True)])})
        # Only this subscription's due time changed: no need to look at all of them (with
        # thousands opened back to back that made opening them quadratic).
        due = self._next_due_ns
        if due is None or sub.next_due_ns < due:
            self._next_due_ns = sub.next_due_ns

    def _sample(self) -> None:
        self._scheduled = False
        snapshot = self._last_snapshot
        if snapshot is None:
            return
        now_ns = snapshot.time_ns
        batches: dict[tuple[Envelope, int], tuple[NotifyFn, list]] = {}
        for sub in list(self._subs.values()):
            if sub.next_due_ns > now_ns:
                continue
            sample = self._take(sub, force=False)
            if sample is not None:
                batches.setdefault((sub.envelope, sub.port), (sub.notify, []))[1].append(sample)
        self._emit(batches)
        self._update_due()

    def _take(self, sub: Subscription, force: bool) -> list | None:
        """Read one subscription; a sample list or None when on-change saw no change."""
        # The read serves whatever snapshot is newest. The stamp must be that snapshot's,
        # so read again in the rare case the kernel published one meanwhile (the cycle
        # thread may take the GIL between any two lines here).
        current = self._current
        while True:
            snapshot = current()
            code, data = self._read(sub.port, sub.group, sub.offset, sub.length)
            if current() is snapshot:
                break
        now_ns = snapshot.time_ns
        # Next due time on the subscription's own grid, never in the past.
        sub.next_due_ns = now_ns - now_ns % sub.cycle_ns + sub.cycle_ns
        if code:
            return None  # the object went away (cannot happen with a fixed catalog)
        if sub.on_change and not force and data == sub.last:
            return None
        sub.last = data  # type: ignore[assignment]
        sub.sequence += 1
        return [sub.handle, sub.sequence, filetime_from_unix_ns(snapshot.wall_ns), data]

    def _emit(self, batches: dict[tuple[Envelope, int], tuple[NotifyFn, list]]) -> None:
        """One frame per client and port with all its samples of this cycle."""
        for (envelope, port), (notify, samples) in batches.items():
            samples = [s for s in samples if s is not None]
            if samples and not notify(envelope, port, samples):
                self.dropped += len(samples)

    def _update_due(self) -> None:
        self._next_due_ns = min((s.next_due_ns for s in self._subs.values()), default=None)
