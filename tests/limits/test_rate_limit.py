"""The token buckets and mailboxes of ``service.rate_limit`` (sans I/O: times are given)."""

from __future__ import annotations

import pytest

from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.frames import BrowseRequest, ReadRequest, ReadWriteRequest
from cnc_objects.service.rate_limit import PRUNE_AT_PEERS, RateLimiter, extra_tokens


def limiter(rate_per_s: float = 10.0, burst: int = 3, mailbox: int = 2,
            mailbox_bytes: int = 1000) -> RateLimiter:
    return RateLimiter(rate_per_s, burst, mailbox, mailbox_bytes)


def test_a_new_client_may_send_its_burst_at_once_then_one_per_token() -> None:
    rate = limiter()
    assert [rate.admit("a", 0.0) for _ in range(4)] == [True, True, True, False]
    assert rate.wait_s("a", 0.0) == pytest.approx(0.1)
    assert not rate.admit("a", 0.05)
    assert rate.admit("a", 0.1)
    assert rate.admit("b", 0.1)  # every client has its own bucket


def test_an_idle_client_saves_up_to_its_burst_only() -> None:
    rate = limiter()
    for _ in range(3):
        rate.admit("a", 0.0)
    assert [rate.admit("a", 100.0) for _ in range(4)] == [True, True, True, False]


def test_requests_over_the_rate_wait_in_order_and_are_released_as_tokens_come() -> None:
    rate = limiter(burst=2, mailbox=5)
    assert rate.admit("a", 0.0) and rate.admit("a", 0.0)
    for k in range(3):
        assert not rate.admit("a", 0.0)
        assert rate.hold("a", f"a{k}", 10)
    assert rate.waiting == 3
    assert list(rate.release(0.05)) == []
    assert rate.next_release_s(0.05) == pytest.approx(0.05)
    assert list(rate.release(0.1)) == ["a0"]
    assert list(rate.release(0.31)) == ["a1", "a2"]
    assert rate.waiting == 0 and rate.next_release_s(0.31) is None


def test_a_client_with_waiting_requests_queues_behind_them_even_with_a_token() -> None:
    rate = limiter(burst=1, mailbox=5)
    rate.admit("a", 0.0)
    rate.admit("a", 0.0)
    rate.hold("a", "first", 10)
    assert not rate.admit("a", 10.0)  # a token is there, but "first" goes first
    rate.hold("a", "second", 10)
    assert list(rate.release(10.0)) == ["first"]


def test_a_full_mailbox_refuses_by_count_and_by_bytes() -> None:
    rate = limiter(burst=1, mailbox=2, mailbox_bytes=100)
    rate.admit("a", 0.0)
    assert rate.hold("a", 1, 10) and rate.hold("a", 2, 10)
    assert not rate.hold("a", 3, 10)  # two wait already
    rate.admit("b", 0.0)
    assert rate.hold("b", 1, 60)
    assert not rate.hold("b", 2, 60)  # 120 bytes would wait
    rate.admit("c", 0.0)
    assert not rate.hold("c", 1, 101)  # more than a whole mailbox
    assert rate.refused == 3 and rate.waited == 3


def test_peers_take_turns_when_released() -> None:
    rate = limiter(rate_per_s=10.0, burst=2, mailbox=5)
    for peer in "ab":
        rate.admit(peer, 0.0)
        rate.admit(peer, 0.0)
        for k in range(2):
            rate.admit(peer, 0.0)
            rate.hold(peer, f"{peer}{k}", 1)
    assert list(rate.release(0.2)) == ["a0", "b0", "a1", "b1"]


def test_an_expensive_request_is_charged_more() -> None:
    rate = limiter(rate_per_s=1000.0, burst=200, mailbox=5)
    rate.admit("a", 0.0)
    rate.charge("a", 99)  # cost 100 tokens; it had paid one
    assert rate.wait_s("a", 0.0) == 0.0  # 100 left of 200
    rate.charge("a", 150)
    assert not rate.admit("a", 0.0)
    assert rate.wait_s("a", 0.0) == pytest.approx((1 + 50) / 1000.0)
    rate.charge("nobody", 5)  # a client never seen: nothing to charge


def test_one_request_takes_at_most_a_full_bucket() -> None:
    """Whatever a request claims to cost, its client waits at most one refill."""
    rate = limiter(rate_per_s=1000.0, burst=10, mailbox=5)
    rate.admit("a", 0.0)
    rate.charge("a", 268_435_455)  # a sum command that claims 0xFFFFFFFF items
    assert rate.wait_s("a", 0.0) == pytest.approx((1 + 10 - 9) / 1000.0)


@pytest.mark.parametrize(("request_", "size_bytes", "tokens"), [
    (ReadRequest(1, CncPort.COM, 0x120100, 0x1011, 4), 40, 0),
    (ReadRequest(1, CncPort.COM, 0x120100, 0x1011, 4), 1023, 0),
    (ReadRequest(1, CncPort.COM, 0x120100, 0x1011, 4), 1024, 1),
    (BrowseRequest(1, CncPort.COM, "*"), 144_507, 141),  # every object of the default machine
    (ReadWriteRequest(1, CncPort.COM, 0xF080, 500, 4000, b"x" * 6000), 10_020, 9 + 31),
    (ReadWriteRequest(1, CncPort.COM, 0xF003, 0, 4, b"name"), 40, 0),  # handle by name
    # the offset claims 0xFFFFFFFF items; 300 bytes hold 25 at most (12 bytes each)
    (ReadWriteRequest(1, CncPort.COM, 0xF082, 0xFFFF_FFFF, 1466, b"x" * 300), 2000, 1 + 1),
])
def test_what_a_request_costs(request_: object, size_bytes: int, tokens: int) -> None:
    assert extra_tokens(request_, size_bytes) == tokens


def test_released_requests_are_charged_before_the_next_is_taken() -> None:
    rate = limiter(rate_per_s=1000.0, burst=100, mailbox=10)
    for _ in range(100):
        rate.admit("a", 0.0)
    for k in range(5):
        rate.admit("a", 0.0)
        rate.hold("a", k, 1)
    served = []
    for item in rate.release(0.1):  # 100 tokens by now
        served.append(item)
        rate.charge("a", 49)  # each costs 50
    assert served == [0, 1]


def test_a_forgotten_client_leaves_nothing_behind() -> None:
    rate = limiter(burst=1)
    rate.admit("a", 0.0)
    rate.admit("a", 0.0)
    rate.hold("a", "x", 1)
    assert rate.forget("a") == ["x"]
    assert len(rate) == 0 and rate.waiting == 0 and rate.next_release_s(0.0) is None


def test_a_client_forgotten_while_its_requests_are_released() -> None:
    rate = limiter(burst=1, mailbox=5)
    rate.admit("a", 0.0)
    for k in range(3):
        rate.admit("a", 0.0)
        rate.hold("a", k, 1)
    released = rate.release(10.0)
    assert next(released) == 0
    assert rate.forget("a") == [1, 2]  # its reply could not be sent: it is gone
    assert list(released) == [] and rate.waiting == 0


def test_idle_clients_are_pruned_so_reconnecting_clients_cost_nothing() -> None:
    rate = limiter(rate_per_s=10.0, burst=1)
    for k in range(10 * PRUNE_AT_PEERS):
        rate.admit(("peer", k), k * 1.0)  # each idle for a second before the next comes
    assert len(rate) < 2 * PRUNE_AT_PEERS


def test_a_charged_client_is_not_pruned_before_it_has_paid() -> None:
    rate = limiter(rate_per_s=0.01, burst=1)
    rate.admit("charged", 0.0)
    rate.charge("charged", 1000)  # a full bucket (the most one request takes): 100 s to pay
    for k in range(2 * PRUNE_AT_PEERS):
        rate.admit(("peer", k), 10.0 + k * 0.001)
    assert not rate.admit("charged", 20.0)


def test_a_rate_limit_needs_a_rate() -> None:
    with pytest.raises(ValueError):
        RateLimiter(0, 1, 1, 1)
