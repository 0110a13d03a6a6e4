"""Request rate per client: a token bucket per peer, and a mailbox for requests over it.

A client may send ``burst`` requests at once and ``rate_per_s`` requests per second on
average. A request that finds its client's bucket empty is not refused: it waits in the
client's mailbox, as an ADS request waits in a TwinCAT router's mailbox, and is served
in order when the bucket has refilled. Only a full mailbox refuses (ADS 0x502, router
mailbox full, as TwinCAT answers a port that is sent more than it takes). So a client
that keeps N requests in flight and waits for the answers is slowed to the rate, never
refused, while a client that sends without waiting is told so.

A request costs one token, about what a read of one object costs the event loop
(10 us). Requests that cost more are charged more (``extra_tokens``), from what the
front end sees once it has served them, without a clock: a token per KiB of request and
reply together (a browse of every object: 141; a program download of 1 MB: 977) and one
per 16 items of a sum command (a sum read of 500 items: 31 more). So a client may use
about ``rate_per_s`` x 10 us of the loop per second (20 % at the default 20 000)
whatever it sends, and the kernel cycle, which needs the GIL the loop holds while it
serves, keeps its rate. The charge comes after the request was served: the client's
next requests wait for what its last one cost.

A mailbox holds at most ``mailbox`` requests and at most ``mailbox_bytes`` bytes: a
client's waiting requests cost bounded memory whatever their size.

The hot path costs one dict lookup and a few float operations per request (``admit``)
and a length comparison for the charge; the caller reads the time once per batch of
requests. Buckets of clients idle long enough to be full again carry no information and
are pruned, so clients that come and go (every ZeroMQ reconnection is a new peer) cost
nothing after a while.

Sans I/O: the caller passes the time and serves what ``release`` hands back.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Hashable, Iterator
from typing import Any

from cnc_objects.protocol.constants import AdsCommand
from cnc_objects.protocol.constants import ReservedIndexGroup as RIG

#: Buckets kept before the first pruning pass; later passes run when the count doubles.
PRUNE_AT_PEERS = 1024
#: Bytes of request and reply that cost one token more (the first KiB is in the request's).
BYTES_PER_TOKEN = 1024
#: Items of a sum command one token pays for.
SUM_ITEMS_PER_TOKEN = 16
#: The least bytes one item of a sum command takes in the request (group, offset, length).
SUM_ITEM_MIN_BYTES = 12
_SUM_GROUPS = frozenset({RIG.SUM_READ, RIG.SUM_WRITE, RIG.SUM_READ_WRITE})
_READ_WRITE = AdsCommand.READ_WRITE


def extra_tokens(request: Any, size_bytes: int) -> int:
    """Tokens a served request costs beyond its first: ``size_bytes`` of request and reply
    together, and the items of a sum command (``ReadWriteRequest`` at 0xF080..0xF082,
    whose index offset is the item count)."""
    extra = size_bytes // BYTES_PER_TOKEN
    if request.COMMAND == _READ_WRITE and request.group in _SUM_GROUPS:
        # The offset only claims a count: no more items are served than the data holds
        # (every item takes 12 bytes or more), so 0xFFFFFFFF items in a short frame cost
        # nothing extra (they are refused as they are).
        items = min(request.offset, len(request.data) // SUM_ITEM_MIN_BYTES)
        extra += items // SUM_ITEMS_PER_TOKEN
    return extra


class _Bucket:
    """Tokens of one peer at ``stamp_s``, and its waiting requests (FIFO)."""

    __slots__ = ("tokens", "stamp_s", "waiting", "waiting_bytes")

    def __init__(self, tokens: float, stamp_s: float) -> None:
        self.tokens = tokens
        self.stamp_s = stamp_s
        self.waiting: deque[Any] | None = None  # None: nothing waits (the common case)
        self.waiting_bytes = 0


class RateLimiter:
    """Token buckets of ``rate_per_s`` and ``burst`` per peer, with a mailbox of
    ``mailbox`` requests and ``mailbox_bytes`` each."""

    def __init__(
        self, rate_per_s: float, burst: int, mailbox: int, mailbox_bytes: int
    ) -> None:
        if rate_per_s <= 0 or burst < 1 or mailbox < 1:
            raise ValueError("a rate limit needs rate_per_s > 0, burst >= 1 and mailbox >= 1")
        self.rate_per_s = float(rate_per_s)
        self.burst = burst
        self.mailbox = mailbox
        self.mailbox_bytes = mailbox_bytes
        self._buckets: dict[Hashable, _Bucket] = {}
        self._waiting_peers: dict[Hashable, _Bucket] = {}  # insertion order: fairness
        self._prune_at = PRUNE_AT_PEERS
        self.waited = 0  # requests that had to wait, since start
        self.refused = 0  # requests refused with a full mailbox, since start

    def __len__(self) -> int:
        return len(self._buckets)

    @property
    def waiting(self) -> int:
        """Requests waiting in all mailboxes."""
        return sum(len(b.waiting or ()) for b in self._waiting_peers.values())

    def admit(self, peer: Hashable, now_s: float) -> bool:
        """Take a token of ``peer`` for a request now: True to serve it at once; False
        when it must wait (no token, or earlier requests of the peer still wait)."""
        bucket = self._buckets.get(peer)
        if bucket is None:
            self._buckets[peer] = _Bucket(self.burst - 1.0, now_s)
            if len(self._buckets) >= self._prune_at:
                self._prune(now_s)
            return True
        if bucket.waiting is not None:
            return False  # keep the peer's order: behind the ones that wait
        tokens = bucket.tokens + (now_s - bucket.stamp_s) * self.rate_per_s
        bucket.stamp_s = now_s
        if tokens >= 1.0:
            bucket.tokens = min(tokens, self.burst) - 1.0
            return True
        bucket.tokens = tokens
        return False

    def charge(self, peer: Hashable, tokens: float) -> None:
        """Take ``tokens`` more from ``peer`` (a request that cost more than one; see
        ``extra_tokens``). The bucket may go below zero: the peer's next requests then
        wait until it has refilled. One request takes at most a full bucket (``burst``):
        however much it claimed, its client waits no longer than a refill."""
        bucket = self._buckets.get(peer)
        if bucket is not None:
            bucket.tokens -= min(tokens, self.burst)

    def hold(self, peer: Hashable, item: Any, size_bytes: int) -> bool:
        """Put a request ``admit`` refused into the peer's mailbox; False when the
        mailbox is full (the request is to be refused)."""
        bucket = self._buckets[peer]
        waiting = bucket.waiting
        if waiting is None:
            if size_bytes > self.mailbox_bytes:
                self.refused += 1
                return False
            bucket.waiting = deque(((item, size_bytes),))
            bucket.waiting_bytes = size_bytes
            self._waiting_peers[peer] = bucket
        elif len(waiting) >= self.mailbox or bucket.waiting_bytes + size_bytes > self.mailbox_bytes:
            self.refused += 1
            return False
        else:
            waiting.append((item, size_bytes))
            bucket.waiting_bytes += size_bytes
        self.waited += 1
        return True

    def release(self, now_s: float) -> Iterator[Any]:
        """The waiting requests that may be served now, one at a time, in order per
        peer, peers taking turns. Each takes its peer's token; a caller that charges a
        request (``charge``) before taking the next makes that peer's next request wait
        for what the last one cost."""
        rate, burst = self.rate_per_s, float(self.burst)
        handed = True
        while handed and self._waiting_peers:
            handed = False
            for peer, bucket in list(self._waiting_peers.items()):
                waiting = bucket.waiting
                if waiting is None:  # forgotten meanwhile
                    continue
                tokens = min(bucket.tokens + (now_s - bucket.stamp_s) * rate, burst)
                bucket.stamp_s = now_s
                if tokens < 1.0:
                    bucket.tokens = tokens
                    continue
                item, size_bytes = waiting.popleft()
                bucket.waiting_bytes -= size_bytes
                bucket.tokens = tokens - 1.0
                if not waiting:
                    bucket.waiting = None
                    bucket.waiting_bytes = 0
                    self._waiting_peers.pop(peer, None)
                handed = True
                yield item  # the caller may charge or forget the peer meanwhile

    def wait_s(self, peer: Hashable, now_s: float) -> float:
        """Seconds from ``now_s`` until ``peer`` has a token again (0: it has one)."""
        bucket = self._buckets.get(peer)
        if bucket is None:
            return 0.0
        tokens = bucket.tokens + (now_s - bucket.stamp_s) * self.rate_per_s
        return max((1.0 - tokens) / self.rate_per_s, 0.0)

    def next_release_s(self, now_s: float) -> float | None:
        """Seconds from ``now_s`` until a waiting request may be served; None when none
        waits."""
        if not self._waiting_peers:
            return None
        rate = self.rate_per_s
        short = min(
            (1.0 - b.tokens - (now_s - b.stamp_s) * rate) for b in self._waiting_peers.values()
        )
        return max(short / rate, 0.0)

    def forget(self, peer: Hashable) -> list[Any]:
        """Drop a peer that is gone; its waiting requests (to be dropped by the caller)."""
        bucket = self._buckets.pop(peer, None)
        self._waiting_peers.pop(peer, None)
        if bucket is None or bucket.waiting is None:
            return []
        waiting, bucket.waiting = bucket.waiting, None
        return [item for item, _ in waiting]

    def _prune(self, now_s: float) -> None:
        """Forget buckets that have refilled (idle peers); pruning again when the count
        doubles keeps the cost per request constant."""
        rate, burst = self.rate_per_s, self.burst
        idle = [  # full again: forgetting them changes nothing (a charged one is kept)
            peer for peer, b in self._buckets.items()
            if b.waiting is None and b.tokens + (now_s - b.stamp_s) * rate >= burst
        ]
        for peer in idle:
            del self._buckets[peer]
        self._prune_at = max(PRUNE_AT_PEERS, 2 * len(self._buckets))
