"""What one page, one session and all pages together may watch through cnc-web.

cnc-web holds the subscriptions of every browser on one connection to the service, and
the service gives one connection at most ``[limits] notifications_per_client`` (1 000 by
default). Without budgets one page could take them all and every other page would get
ADS 0x716 instead of values; one page could also keep cnc-web (and through it the
service) busy subscribing and unsubscribing. So:

- ``names_per_page``: the objects one WebSocket may watch at once;
- ``names_per_session``: the objects all WebSockets of one session (one signed cookie:
  a browser's tabs) may watch at once, so that no session takes another's;
- ``names_total``: the objects cnc-web subscribes to for all pages together, kept under
  the service's ``notifications_per_client``;
- ``names_per_s``: the names one WebSocket's messages may carry per second on average
  (watch and unwatch together; one second's worth at once). A page over it is not
  refused: cnc-web reads its next message later (TCP holds the rest), so a page that
  watches and unwatches in a loop gets cnc-web's time at this rate and no more;
- ``subscribes_in_flight``: subscribe requests cnc-web keeps out to the service at once;
  unsubscribes go one at a time. Another request of an operator (a RESET) waits behind
  at most these, however many names the pages watch and unwatch;
- ``linger_s``: how long a subscription nobody watches any more is kept before it is
  deleted; a page that watches the name again meanwhile gets it at no cost.

A name over a budget is refused in the ``errors`` of the page's next message with a
sentence saying which budget (``refusal``); the others are watched. An unknown name is
refused from the catalogue cached in the client, without a search for the nearest names.
Defaults and what a page gets: docs/web.md, section "Watch budgets".
"""

from __future__ import annotations

import asyncio
import math
from collections.abc import Callable
from dataclasses import dataclass

NAMES_PER_PAGE = 200  # a machine page of 4 channels x 8 axes watches about 190
NAMES_PER_SESSION = 400  # two such pages open in one browser
NAMES_TOTAL = 900  # under the service's default notifications_per_client (1 000)
NAMES_PER_S = 1000.0  # a page watches its ~200 names at once, then a few a second
SUBSCRIBES_IN_FLIGHT = 4  # a RESET waits behind at most 4 subscribe requests
GONE_CHECK_S = 0.25  # a page over its rate that left is noticed this soon
LINGER_S = 5.0  # wall time an unwatched subscription is kept for a page that comes back


@dataclass(frozen=True, slots=True)
class WatchBudgets:
    """The budgets of one cnc-web server (see the module docstring)."""

    names_per_page: int = NAMES_PER_PAGE
    names_per_session: int = NAMES_PER_SESSION
    names_total: int = NAMES_TOTAL
    names_per_s: float = NAMES_PER_S
    subscribes_in_flight: int = SUBSCRIBES_IN_FLIGHT
    linger_s: float = LINGER_S

    def __post_init__(self) -> None:
        for name in ("names_per_page", "names_per_session", "names_total",
                     "subscribes_in_flight"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be at least 1")
        if not (math.isfinite(self.names_per_s) and self.names_per_s > 0):
            raise ValueError(f"names_per_s must be a number more than 0, not {self.names_per_s}")
        if not (math.isfinite(self.linger_s) and self.linger_s >= 0):
            raise ValueError(f"linger_s must be a number 0 or more, not {self.linger_s}")

    def refusal(self, budget: str) -> str:
        """The sentence a page gets for a name over ``budget`` (a field's name)."""
        match budget:
            case "names_per_page":
                return (f"refused by cnc-web: this page watches {self.names_per_page} "
                        "objects, the most one page may (--watch-per-page); unwatch some first")
            case "names_per_session":
                return (f"refused by cnc-web: this session's pages watch "
                        f"{self.names_per_session} objects, the most one session may "
                        "(--watch-per-session); unwatch some first")
            case _:
                return (f"refused by cnc-web: all pages together watch {self.names_total} "
                        "objects, the most cnc-web subscribes to (--watch-total); try again "
                        "when other pages watch fewer")


class NameRate:
    """The token bucket of one WebSocket: ``names_per_s`` names a second, as many at once."""

    def __init__(self, names_per_s: float) -> None:
        self._rate = names_per_s
        self._tokens = names_per_s
        self._stamp_s = asyncio.get_running_loop().time()

    async def spend(self, names: int, gone: Callable[[], bool]) -> bool:
        """Take ``names`` tokens, waiting first while the bucket is in debt (the caller
        reads nothing meanwhile: the page's next messages wait in TCP). False when
        ``gone()`` says the page left while it waited: its messages need no answer."""
        loop = asyncio.get_running_loop()
        now_s = loop.time()
        self._tokens = min(self._rate, self._tokens + (now_s - self._stamp_s) * self._rate)
        self._stamp_s = now_s
        until_s = now_s - self._tokens / self._rate
        while loop.time() < until_s:
            if gone():
                return False
            await asyncio.sleep(min(GONE_CHECK_S, until_s - loop.time()))
        if self._tokens < 0:
            self._tokens, self._stamp_s = 0.0, loop.time()
        self._tokens -= names
        return not gone()
