"""Sign-in without stalling cnc-web: password hashing off the event loop, rate-limited.

An Argon2id check costs 64 MiB and some 100 ms of CPU on purpose. Run on the event loop
it would stop every other browser's reads while it runs, and parallel attempts would add
64 MiB each. So:

- hashes are checked in a pool of ``HASH_WORKERS`` threads (argon2-cffi releases the GIL)
  of lower priority than the event loop (nice ``HASH_NICENESS``);
  at most ``MAX_WAITING`` attempts wait for it, more are answered 429 at once;
- each client address and each role (the user name of cnc-web) has a token bucket of
  attempts: ``BURST`` at once, then one per ``REFILL_S``; an attempt without a token
  is answered 429 with ``Retry-After`` before any hashing. The role's bucket is larger
  than an address's: one address cannot lock a role out, many addresses are slowed.
"""

from __future__ import annotations

import asyncio
import contextlib
import math
import os
import threading
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

HASH_WORKERS = 1  # Argon2id checks at once (each 64 MiB, itself 4 lanes)
HASH_NICENESS = 10  # the hashing threads' nice value: below the event loop's
MAX_WAITING = 8  # attempts hashing or waiting for the pool; beyond: 429
MAX_TRACKED = 10_000  # addresses remembered; beyond, full buckets are forgotten first


@dataclass(frozen=True, slots=True)
class BucketRule:
    """A token bucket's size and refill: ``burst`` attempts at once, then one per
    ``refill_s`` seconds."""

    burst: int
    refill_s: float


PER_ADDRESS = BucketRule(burst=5, refill_s=12.0)  # 5 at once, then 5 a minute
PER_ROLE = BucketRule(burst=20, refill_s=3.0)  # 20 at once, then 20 a minute


@dataclass(slots=True)
class _Bucket:
    tokens: float
    stamp_s: float


@dataclass
class Buckets:
    """One token bucket per key (an address, a role), filled as time passes."""

    rule: BucketRule
    clock: Callable[[], float] = time.monotonic
    _buckets: dict[str, _Bucket] = field(default_factory=dict)

    def _refilled(self, key: str) -> _Bucket:
        now = self.clock()
        bucket = self._buckets.get(key)
        if bucket is None:
            if len(self._buckets) >= MAX_TRACKED:
                self._forget_full(now)
            bucket = self._buckets[key] = _Bucket(float(self.rule.burst), now)
        bucket.tokens = min(self.rule.burst,
                            bucket.tokens + (now - bucket.stamp_s) / self.rule.refill_s)
        bucket.stamp_s = now
        return bucket

    def _forget_full(self, now_s: float) -> None:
        full_after_s = self.rule.burst * self.rule.refill_s
        for key in [k for k, b in self._buckets.items() if now_s - b.stamp_s >= full_after_s]:
            del self._buckets[key]

    def wait_s(self, key: str) -> float:
        """0 when ``key`` has an attempt left, else the seconds until it has one."""
        bucket = self._refilled(key)
        return 0.0 if bucket.tokens >= 1 else (1 - bucket.tokens) * self.rule.refill_s

    def take(self, key: str) -> None:
        """Use one of ``key``'s attempts (check ``wait_s`` first)."""
        self._refilled(key).tokens -= 1


def _yield_to_the_event_loop() -> None:
    """Lower this hashing thread's priority (Linux: per thread; Argon2's lane threads
    inherit it), so that the CPU goes to the event loop first when both want it."""
    with contextlib.suppress(OSError, AttributeError):
        os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), HASH_NICENESS)


class TooManyAttempts(Exception):
    """Refused before hashing; ``retry_after_s``: when to try again (whole seconds)."""

    def __init__(self, reason: str, retry_after_s: float) -> None:
        self.retry_after_s = max(1, math.ceil(retry_after_s))
        super().__init__(f"{reason}: try again in {self.retry_after_s} s")


class SignInGate:
    """Decides whether an attempt may be hashed now, and hashes it off the event loop."""

    def __init__(self, per_address: BucketRule = PER_ADDRESS, per_role: BucketRule = PER_ROLE,
                 workers: int = HASH_WORKERS, max_waiting: int = MAX_WAITING) -> None:
        self.addresses = Buckets(per_address)
        self.roles = Buckets(per_role)
        self.max_waiting = max_waiting
        self._pool = ThreadPoolExecutor(workers, thread_name_prefix="cnc-web-argon2",
                                        initializer=_yield_to_the_event_loop)
        self._waiting = 0

    def admit(self, address: str, role: str) -> None:
        """Take an attempt of ``address`` and of ``role``; ``TooManyAttempts`` (nothing
        taken) when either has none left or too many attempts wait for the hasher."""
        for buckets, key, whose in ((self.addresses, address, f"address {address}"),
                                    (self.roles, role, f"role {role}")):
            wait_s = buckets.wait_s(key)
            if wait_s > 0:
                raise TooManyAttempts(f"too many sign-in attempts from {whose}", wait_s)
        if self._waiting >= self.max_waiting:
            raise TooManyAttempts("too many sign-ins at once", 1)
        self.addresses.take(address)
        self.roles.take(role)

    async def check(self, verify: Callable[[], bool]) -> bool:
        """``verify()`` (the password hash check) in the pool; the event loop goes on."""
        self._waiting += 1
        try:
            return await asyncio.get_running_loop().run_in_executor(self._pool, verify)
        finally:
            self._waiting -= 1

    def close(self) -> None:
        """Stop the pool (attempts under way finish)."""
        self._pool.shutdown(wait=False, cancel_futures=True)
