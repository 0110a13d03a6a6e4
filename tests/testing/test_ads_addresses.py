"""Services that serve ADS one after another in one test process each get a loopback
address none of them had: pyads' router (AdsLib) keeps its connection to an address after
the service there stopped, and pyads then gets no answer from a later service at the same
address ("timeout elapsed (1861)", reproduced with two services at one address; the
likely cause of a rare failure of tests/e2e/test_plc_functions_pyads.py when two pyads
modules in one pytest-xdist worker drew the same address at random)."""

from __future__ import annotations

from cnc_objects.testing.process import free_loopback_ads_address


def test_no_address_is_given_twice_while_fresh_ones_are_left() -> None:
    given = [free_loopback_ads_address() for _ in range(60)]
    # at random among 253 addresses, 60 draws repeat one with a probability of 0.999
    assert len(set(given)) == len(given)
    assert all(a.startswith("127.0.0.") and a.endswith(":48898") for a in given)

