"""``Kernel.reading``: a thread pins one snapshot, so that many reads (a notification
pass) see one cycle however many the kernel publishes meanwhile; other threads see the
newest (issue 35: the hub read again until no cycle was published during its read, which
a read longer than a cycle never met)."""

from __future__ import annotations

import threading
from collections.abc import Iterator

import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.clock import VirtualClock
from cnc_objects.service.kernel.commands import SetFeedOverride
from cnc_objects.service.kernel.kernel import Kernel
from cnc_objects.service.kernel.state import Snapshot
from tests.support.kernel_commands import submit


@pytest.fixture
def kernel() -> Iterator[Kernel]:
    k = Kernel(build_config(), VirtualClock(0.001))
    k.start()
    yield k
    k.close()


def seen_by_another_thread(kernel: Kernel) -> Snapshot:
    """``kernel.snapshot`` as a thread without a pin reads it."""
    seen: list[Snapshot] = []
    reader = threading.Thread(target=lambda: seen.append(kernel.snapshot))
    reader.start()
    reader.join()
    return seen[0]


def test_a_pinned_snapshot_holds_on_its_thread_only(kernel: Kernel) -> None:
    with kernel.reading() as pinned:
        assert submit(kernel, SetFeedOverride(0, 420)) is None  # published after pinning
        assert kernel.snapshot is pinned
        assert pinned.channels[0].switches.feed_override_per_mille == 1000
        newest = seen_by_another_thread(kernel)
        assert newest.cycle > pinned.cycle
        assert newest.channels[0].switches.feed_override_per_mille == 420
    assert kernel.snapshot.channels[0].switches.feed_override_per_mille == 420  # unpinned


def test_a_given_snapshot_is_pinned_and_a_nested_block_keeps_the_outer_pin(
    kernel: Kernel
) -> None:
    old = kernel.snapshot
    assert submit(kernel, SetFeedOverride(0, 420)) is None
    with kernel.reading(old) as pinned:
        assert pinned is old and kernel.snapshot is old
        with kernel.reading() as inner:
            assert inner is old
        assert kernel.snapshot is old  # the inner block did not unpin
    assert kernel.snapshot is not old
