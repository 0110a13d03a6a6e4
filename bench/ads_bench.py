"""``make bench`` ADS part: pyads against the minimal echo server, then against the service.

In one run: pyads sequential ``Connection.read`` of one object (``ch1.ax1.link_state``,
UDINT) against ``ads_echo`` (a second process answering every frame with a fixed Read
reply: the baseline), then against the real ``cnc-service`` (realtime clock, 1 ms cycle,
a second process) on the same object; and ``read_list_by_name`` of 100 symbols against
the service. Each server has a loopback address of its own (AdsLib always dials port
48898). Figures are medians over the runs; the ratio is taken within each run (the
baseline is measured right before the service), its median printed. Targets: sequential
reads >= 0.8 of the baseline, read_list_by_name(100) >= 20,000 symbols/s.
"""

from __future__ import annotations

import multiprocessing as mp
import statistics
import sys
import tempfile
import time
from pathlib import Path

import pyads

from cnc_objects.clients import Client
from cnc_objects.testing.process import free_loopback_ads_address, start_service

from .ads_echo import serve_ads_echo
from .common import BENCH_MACHINE, Figure, figure, median_figure

LOCAL_NET_ID = "127.0.0.1.1.30"
OBJECT = (551, 0x121301, 0x10018)  # ch1.ax1.link_state, UDINT
LIST_SIZE = 100
SEQUENTIAL_TARGET = 0.8
SYMBOLS_S_TARGET = 20_000


def sequential(connection: pyads.Connection, count: int) -> Figure:
    """``count`` reads one after the other."""
    _, group, offset = OBJECT
    read = connection.read
    for _ in range(200):  # warm up
        read(group, offset, pyads.PLCTYPE_UDINT)
    lat = []
    clock = time.perf_counter
    start = clock()
    for _ in range(count):
        t0 = clock()
        read(group, offset, pyads.PLCTYPE_UDINT)
        lat.append(clock() - t0)
    return figure(count, clock() - start, lat)


def read_list(connection: pyads.Connection, names: list[str], count: int) -> Figure:
    """``count`` calls of ``read_list_by_name(names)`` (one sum read each)."""
    connection.read_list_by_name(names)  # symbol information cached once, as pyads does
    lat = []
    clock = time.perf_counter
    start = clock()
    for _ in range(count):
        t0 = clock()
        connection.read_list_by_name(names)
        lat.append(clock() - t0)
    return figure(count, clock() - start, lat)


def _connection(address: str, port: int) -> pyads.Connection:
    host = address.rsplit(":", 1)[0]
    connection = pyads.Connection(f"{host}.1.1", port, host)
    connection.open()
    return connection


def main(runs: int, count: int) -> None:
    """Measure and print the table."""
    echo_address = free_loopback_ads_address()
    host, port = echo_address.rsplit(":", 1)
    ctx = mp.get_context("spawn")
    ready = ctx.Queue()
    echo = ctx.Process(target=serve_ads_echo, args=(host, int(port), ready), daemon=True)
    echo.start()
    status = ready.get(timeout=20)
    if status is not True:
        raise RuntimeError(f"the ADS echo server could not listen on {echo_address}: {status}")
    with tempfile.TemporaryDirectory() as tmp:
        machine = Path(tmp) / "bench.toml"
        machine.write_text(BENCH_MACHINE)
        service = start_service("--clock", "realtime", "--config", str(machine), ads=True)
    pyads.open_port()
    pyads.set_local_address(LOCAL_NET_ID)
    connections = []
    try:
        ads_host, ads_port = service.ads_address  # type: ignore[misc]
        service_address = f"{ads_host}:{ads_port}"
        baseline = _connection(echo_address, OBJECT[0])
        ours = _connection(service_address, OBJECT[0])
        plc = _connection(service_address, 851)
        connections = [baseline, ours, plc]
        with Client(service.endpoint) as client:
            names = [o.name for o in client.browse() if o.access != "w"][:LIST_SIZE]
        figures: dict[str, list[Figure]] = {"echo": [], "ours": [], "list": []}
        ratios = []
        for run in range(runs):
            echo_fig = sequential(baseline, count)
            our_fig = sequential(ours, count)
            figures["echo"].append(echo_fig)
            figures["ours"].append(our_fig)
            figures["list"].append(read_list(plc, names, max(50, count // 20)))
            ratios.append(our_fig.reads_s / echo_fig.reads_s)
            print(f"run {run + 1}/{runs}: sequential {ratios[-1]:.2f} of the echo, "
                  f"read_list_by_name({len(names)}) "
                  f"{figures['list'][-1].reads_s * len(names):,.0f} symbols/s", file=sys.stderr)
    finally:
        for connection in connections:
            connection.close()
        pyads.close_port()
        service.stop()
        echo.terminate()
    _report({k: median_figure(v) for k, v in figures.items()}, statistics.median(ratios),
            len(names), runs)


def _report(fig: dict[str, Figure], ratio: float, n_names: int, runs: int) -> None:
    symbols_s = fig["list"].reads_s * n_names
    print(f"\nADS over AMS/TCP with pyads {pyads.__version__}: median of {runs} runs; ratio: "
          "median of the per-run ratios to the echo server\n")
    print(f"{'measurement':40} {'reads/s':>10} {'ratio':>6} {'median us':>10} {'p99 us':>9}  target")
    rows = [
        ("ADS echo server, sequential (baseline)", fig["echo"], 1.0, ""),
        ("cnc-service, sequential", fig["ours"], ratio,
         f">= {SEQUENTIAL_TARGET}: " + ("met" if ratio >= SEQUENTIAL_TARGET else "NOT met")),
        (f"read_list_by_name({n_names}) calls", fig["list"], None, ""),
    ]
    for label, f, r, verdict in rows:
        shown = f"{r:6.2f}" if r is not None else f"{'':6}"
        print(f"{label:40} {f.reads_s:10.0f} {shown} {f.median_us:10.1f} {f.p99_us:9.1f}  {verdict}")
    print(f"\nread_list_by_name: {symbols_s:,.0f} symbols/s ({n_names} per call) "
          f">= {SYMBOLS_S_TARGET:,}: {'met' if symbols_s >= SYMBOLS_S_TARGET else 'NOT met'}")
