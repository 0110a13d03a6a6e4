"""Update latency of the HMI: from an object's change in the service to the widget.

    python -m cnc_objects.clients.hmi.latency --endpoint tcp://127.0.0.1:5598 \
        [--count 50] [--moving]

A second client writes ``ch1.mc_command_feed_override_w`` alternately to two values; the
HMI runs headless (``App.run_test``) in the same process. Each change is timed from the
write being sent, and from its acknowledgement (the kernel has applied it: the object has
changed), until the channel table's override cell holds the new text (polled every
``POLL_S``; painting follows within one frame, 1/60 s). ``--moving`` runs a long program
in channel 1 meanwhile, so the HMI is also busy with position samples.
"""

from __future__ import annotations

import asyncio
import statistics
import time

import typer

from cnc_objects.clients.client import DEFAULT_ENDPOINT, AsyncClient

from . import text
from .app import HmiApp

POLL_S = 0.0005  # resolution of "the cell shows it"
VALUES_01PCT = (730, 740)  # two overrides (0.1 %) the measurement alternates between
_MOVING = b"G90 G1 X50 Y50 F60\nG1 X0 Y0\nM30\n"  # 2 x 70.7 mm at 1 mm/s


async def measure(endpoint: str, count: int, moving: bool) -> dict[str, list[float]]:
    """Latencies in seconds, ``sent`` (write sent -> shown) and ``acked`` (ack -> shown)."""
    app = HmiApp(endpoint)
    result: dict[str, list[float]] = {"sent": [], "acked": []}
    async with AsyncClient(endpoint) as client, app.run_test(size=(110, 40)):
        await _until(lambda: app.client is not None and app.channels.row_count > 0, 30)
        if moving:
            await client.reset(1)
            await client.upload("hmi-latency.nc", _MOVING)
            await client.run_program("hmi-latency.nc")
        for k in range(count + 1):
            value = VALUES_01PCT[k % 2]
            shown = text.percent(value)
            t_sent = time.perf_counter()
            await client.write("ch1.mc_command_feed_override_w", value)
            t_acked = time.perf_counter()
            await _until(lambda: app.channels.cell("ch1", "override") == shown, 10)
            t_shown = time.perf_counter()
            if k:  # the first change also waits for the table to fill: not a sample
                result["sent"].append(t_shown - t_sent)
                result["acked"].append(t_shown - t_acked)
        if moving:
            await client.reset(1)
    return result


async def _until(predicate: object, timeout_s: float) -> None:
    deadline = time.perf_counter() + timeout_s
    while not predicate():  # type: ignore[operator]
        if time.perf_counter() > deadline:
            raise TimeoutError("the HMI did not show the change")
        await asyncio.sleep(POLL_S)


cli = typer.Typer(add_completion=False)


@cli.command()
def run(
    endpoint: str = typer.Option(
        DEFAULT_ENDPOINT, "--endpoint", metavar="URL", help="The cnc-service to measure against."
    ),
    count: int = typer.Option(50, "--count", min=1, help="Changes to time."),
    moving: bool = typer.Option(False, "--moving", help="Run a program in channel 1 meanwhile."),
) -> None:
    """Time an object change from the service to the HMI's widget; print median, 90th
    percentile and maximum in ms."""
    result = asyncio.run(measure(endpoint, count, moving))
    for name, samples in result.items():
        ms = sorted(s * 1000 for s in samples)
        p90 = ms[int(0.9 * (len(ms) - 1))]
        print(f"{name:>5} -> shown: median {statistics.median(ms):.2f} ms, "
              f"p90 {p90:.2f} ms, max {ms[-1]:.2f} ms ({len(ms)} changes)")


def main(argv: list[str] | None = None) -> None:
    """Entry point of ``python -m cnc_objects.clients.hmi.latency``."""
    cli(args=argv, prog_name="python -m cnc_objects.clients.hmi.latency")


if __name__ == "__main__":
    main()
