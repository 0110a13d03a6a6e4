"""No client request waits on the kernel's backlog (issue 25): the START of a program
whose decoder loops without producing blocks is answered as soon as the kernel has
applied it, and the RESET after it too.

With the virtual clock the cycle that begins a run waits for the decoder's first blocks
(so that the run is the same cycle by cycle). A ``$WHILE 1`` without motion gives none
until the decoder's endless-loop guard (a million passes, 10-30 s on a loaded machine),
and the START's reply once waited with that cycle: the NC fuzz's client timed out.
"""

from __future__ import annotations

import time

import pytest

from cnc_objects.clients import AsyncClient
from cnc_objects.protocol.values import ChannelState
from cnc_objects.testing import serving
from cnc_objects.testing.helpers import wait_for_async

REPLY_MAX_S = 2.0  # START and RESET are answered within this
CLIENT_TIMEOUT_S = 30.0  # the client's own timeout: longer than the loop guard
#: endless loops without motion (every variable must be declared, hence the #VAR)
LOOPS = {
    "idle": "$WHILE 1\n$ENDWHILE\nM30\n",
    "variable": "#VAR\nV.L.N = 0\n#ENDVAR\n$WHILE 1\nV.L.N = V.L.N + 1\n$ENDWHILE\nM30\n",
}


@pytest.mark.parametrize("kind", sorted(LOOPS))
async def test_start_of_a_loop_without_motion_is_answered_at_once(kind: str) -> None:
    """START, then RESET, of an endless ``$WHILE`` without motion: each reply within
    ``REPLY_MAX_S``; the channel is READY after the RESET."""
    with serving() as service:
        async with AsyncClient(service.endpoint, timeout_s=CLIENT_TIMEOUT_S) as c:
            await c.upload("loop.nc", LOOPS[kind].encode())
            started_s = time.monotonic()
            await c.run_program("loop.nc")
            start_reply_s = time.monotonic() - started_s
            assert start_reply_s < REPLY_MAX_S, f"START answered after {start_reply_s:.1f} s"
            assert await c.read("ch1.mc_active_state_r") == ChannelState.ACTIVE
            started_s = time.monotonic()
            await c.reset()
            reset_reply_s = time.monotonic() - started_s
            assert reset_reply_s < REPLY_MAX_S, f"RESET answered after {reset_reply_s:.1f} s"
            await wait_for_async(c, "ch1.mc_active_state_r",
                                 lambda state: state == ChannelState.READY, timeout_s=10.0)
