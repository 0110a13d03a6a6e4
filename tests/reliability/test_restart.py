"""Restart on the same endpoint at once: the new service binds the port the old one just
left, and clients that stay connected across the restart are answered again (a ZeroMQ
DEALER reconnects by itself) without being opened anew.
"""

from __future__ import annotations

import time

from cnc_objects.clients import AsyncClient, NoReplyError
from cnc_objects.testing import start_service
from tests.reliability import figures
from tests.reliability.scale import Scale
from tests.support.broker import free_port

REQUEST_TIMEOUT_S = 5.0  # a client's request; one sent while no service runs times out
RECONNECT_TIMEOUT_S = 30.0  # the staying client must be answered again within this
NODE = "tests/reliability/test_restart.py"


async def answered(client: AsyncClient, timeout_s: float) -> float:
    """Seconds until ``client`` gets an answer to a read again (requests that fall
    into the gap time out and are sent again, up to ``timeout_s``)."""
    started = time.monotonic()
    while True:
        try:
            assert await client.read("cnc_tick_counter_r") >= 0
            return time.monotonic() - started
        except NoReplyError:
            assert time.monotonic() - started < timeout_s, "no answer after the restart"


async def test_a_restart_on_the_same_endpoint_serves_the_clients_that_stayed(
    run_scale: Scale,
) -> None:
    endpoint = f"tcp://127.0.0.1:{free_port()}"
    service = start_service("--endpoint", endpoint)
    restart_s, answer_s = [], []
    try:
        async with AsyncClient(endpoint, timeout_s=REQUEST_TIMEOUT_S) as client:
            await client.write("ch1.mc_command_feed_override_w", 500)
            for _ in range(run_scale.restarts):
                assert await client.read("ch1.mc_command_feed_override_r") == 500
                stopped = time.monotonic()
                assert service.stop() == 0, service.log_text
                service = start_service("--endpoint", endpoint)  # at once, same port
                restart_s.append(time.monotonic() - stopped)
                answer_s.append(await answered(client, RECONNECT_TIMEOUT_S))
                # a new service: the state is the configured one, not the old one's
                assert await client.read("ch1.mc_command_feed_override_r") == 1000
                await client.write("ch1.mc_command_feed_override_w", 500)
    finally:
        assert service.stop() == 0, service.log_text
    print(f"\n{run_scale.restarts} restarts on {endpoint}: stop and listening again in "
          f"{max(restart_s):.2f} s at most; the staying client answered "
          f"{max(answer_s):.2f} s after that at most")
    figures.record("restarts on one endpoint: down time, staying client answered after",
                   f"{run_scale.restarts} x, <= {max(restart_s):.2f} s, <= {max(answer_s):.2f} s",
                   NODE)
