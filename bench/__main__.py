"""``make bench``: request dispatch against a raw ZeroMQ echo, and the kernel's hot paths.

Kernel part (``--part kernel``): the decoder against a ``str.split`` tokenizer of the same
200,000-line file (``bench/decoder_bench.py``), the interpolator in simulated seconds per
wall second (``bench/kernel_bench.py``), and the planner's machining time against the
whole-program optimum of the same model (``bench/planner_bench.py``).

Look-ahead part (``--part lookahead``): ``ch1.program_time`` of the look-ahead programs
on the kernel against the time-optimal limit of a separate reference implementation,
LA_OFF with 30/120/190 blocks and LA_ON (``bench/lookahead_bench.py``); it writes the
spiral's speed plot to ``lookahead-spiral.png``.

ADS part (``--part ads``): pyads sequential reads against a minimal asyncio AMS/TCP
echo server and against the service, and ``read_list_by_name`` of 100 symbols
(``bench/ads_bench.py``); then by-name reads on a fresh connection with each ADS client
the tests run, against pyads', and the time to upload and read every symbol
(``bench/ads_clients_bench.py``).

Client part (``--part client``): ``AsyncClient`` bursts and sliding window, batched and
not, against the raw pipelined echo in the same run, in reads/s and in CPU time per read
of each process (``bench/client_bench.py``; issue 30).
Jitter part (``--part jitter``): the realtime cycle's lateness (p50, p99, max) and
overruns while the service answers 5 000 reads/s and feeds 20 on-change subscriptions
during a run, and while an idle service answers browses of the whole catalogue
(``bench/jitter_bench.py``); its rows of the virtual part's table (issue 37) are printed
there and again under that table when both parts run (``make bench``).
Virtual part (``--part virtual``): simulated seconds per wall second of the whole service
on the virtual clock for the pocket and a one-hour part, with no and with 20 on-change
subscriptions, and with cnc-web attached and one browser session (``bench/virtual_bench.py``);
then the short blocks (also ``--part short-blocks`` alone): a 10 000-block spiral and a
CAM finishing program of 115 000 blocks (``bench/programs/cam_finish.py``).
Fairness part (``--part fairness``): another client's read latency while one client
holds every notification the service takes (20 000 cyclic, 1 ms), idle and loaded
(``bench/fairness_bench.py``; target p99 < 10 ms); then beside a monitor's large
on-change notifications of the PLC memory area (``bench/notification_size_bench.py``).
CLI part (``--part cli``): ``cnc --help`` and ``cnc read`` of one object, start to exit,
against ``python -c pass`` and ``python -c 'import zmq'`` (``bench/cli_bench.py``; target
< 0.25 s each).
Idle part (``--part idle``): the kernel's idle cycle in microseconds, resting and with
its whole work, and an idle realtime ``cnc-service``'s CPU % and memory, against a bare
1 ms sleep loop (``bench/idle_bench.py``; issue 36).
Web part (``--part web``): cnc-web's position update rate in 10 WebSocket sessions while a
program runs, and the realtime cycle's figures without and with it (``bench/web_bench.py``).
Dispatch part (``--part dispatch``):

Baseline: a raw pyzmq ROUTER in a second process that answers each msgpack frame with a
reply of the same shape as ours (sync sockets, no dispatch), driven by a sync DEALER:
sequential round trips, and 64 frames in flight. Then the real ``cnc-service``
(realtime clock, 1 ms cycle, in a second process) driven by:

* ``Client.read_address`` sequentially,
* ``AsyncClient.read_address`` from 64 coroutines (64 reads in flight, a sliding
  window), and in bursts (``asyncio.gather`` of 64, then the next burst: one sum read,
  the client batches, issue 30); both also with ``batch=False`` (a frame per read), and
  unbatched against the raw echo, which shows the client's own share (the service's is
  the rest),
* ``AsyncClient.read_many`` of 100 objects (one sum read each).

Every figure is the median over ``--runs`` runs (default 5). Each run measures the
baseline right before the project's figure, and the ratio is taken within the run (the
machines are noisy: paired figures cancel most of the drift); the ratio printed is the
median of the per-run ratios. Targets: sequential >= 0.6 of the raw echo, 64 in
flight >= 0.8 of the raw pipelined echo.
"""

from __future__ import annotations

import argparse
import asyncio
import multiprocessing as mp
import statistics
import sys
import tempfile
import time
from pathlib import Path

import msgpack
import zmq

from cnc_objects.clients import AsyncClient, Client
from tests.support.service import start_service

from .common import BENCH_MACHINE, Figure, figure, median_figure
from .raw_echo import serve_echo

ADDRESS = (551, 0x121301, 0x10018, "UNS32")  # ch1.ax1.link_state
IN_FLIGHT = 64

def _frame(invoke_id: int) -> bytes:
    return msgpack.packb([invoke_id, 2, *ADDRESS[:3], 4])


def raw_sequential(endpoint: str, count: int) -> Figure:
    """Sync DEALER, one frame at a time."""
    ctx = zmq.Context()
    sock = ctx.socket(zmq.DEALER)
    sock.connect(endpoint)
    for k in range(200):  # connect and warm up
        sock.send(_frame(k + 1))
        sock.recv()
    lat = []
    start = time.perf_counter()
    for k in range(count):
        t0 = time.perf_counter()
        sock.send(_frame(k + 1))
        msgpack.unpackb(sock.recv())
        lat.append(time.perf_counter() - t0)
    elapsed = time.perf_counter() - start
    sock.close(linger=0)
    ctx.term()
    return figure(count, elapsed, lat)


def raw_pipelined(endpoint: str, count: int) -> Figure:
    """Sync DEALER keeping IN_FLIGHT frames outstanding."""
    ctx = zmq.Context()
    sock = ctx.socket(zmq.DEALER)
    sock.connect(endpoint)
    for k in range(200):
        sock.send(_frame(k + 1))
        sock.recv()
    sent_at: dict[int, float] = {}
    lat = []
    start = time.perf_counter()
    sent = 0
    for _ in range(IN_FLIGHT):
        sent += 1
        sent_at[sent] = time.perf_counter()
        sock.send(_frame(sent))
    for _ in range(count):
        reply = msgpack.unpackb(sock.recv())
        lat.append(time.perf_counter() - sent_at.pop(reply[0]))
        if sent < count:
            sent += 1
            sent_at[sent] = time.perf_counter()
            sock.send(_frame(sent))
    elapsed = time.perf_counter() - start
    sock.close(linger=0)
    ctx.term()
    return figure(count, elapsed, lat)


def client_sequential(endpoint: str, count: int) -> Figure:
    """The blocking client, one read at a time."""
    with Client(endpoint) as c:
        for _ in range(200):
            c.read_address(*ADDRESS)
        lat = []
        start = time.perf_counter()
        for _ in range(count):
            t0 = time.perf_counter()
            c.read_address(*ADDRESS)
            lat.append(time.perf_counter() - t0)
        elapsed = time.perf_counter() - start
    return figure(count, elapsed, lat)


async def _client_in_flight(endpoint: str, count: int, batch: bool) -> Figure:
    async with AsyncClient(endpoint, batch=batch) as c:
        await asyncio.gather(*(c.read_address(*ADDRESS) for _ in range(200)))
        lat: list[float] = []
        per_worker = count // IN_FLIGHT

        async def worker() -> None:
            clock = time.perf_counter
            for _ in range(per_worker):
                t0 = clock()
                await c.read_address(*ADDRESS)
                lat.append(clock() - t0)

        start = time.perf_counter()
        await asyncio.gather(*(worker() for _ in range(IN_FLIGHT)))
        elapsed = time.perf_counter() - start
    return figure(per_worker * IN_FLIGHT, elapsed, lat)


def client_in_flight(endpoint: str, count: int, batch: bool = True) -> Figure:
    """AsyncClient with IN_FLIGHT reads outstanding (a sliding window: each of IN_FLIGHT
    coroutines sends its next read when its last one is answered; with ``batch``, the
    reads that meet in one loop turn share a sum read)."""
    return asyncio.run(_client_in_flight(endpoint, count, batch))


async def _client_bursts(endpoint: str, count: int, batch: bool) -> Figure:
    async with AsyncClient(endpoint, batch=batch) as c:
        await asyncio.gather(*(c.read_address(*ADDRESS) for _ in range(200)))
        lat: list[float] = []
        bursts = count // IN_FLIGHT
        clock = time.perf_counter
        start = clock()
        for _ in range(bursts):
            t0 = clock()
            await asyncio.gather(*(c.read_address(*ADDRESS) for _ in range(IN_FLIGHT)))
            lat.append(clock() - t0)  # a burst's latency: its last reply
        elapsed = clock() - start
    return figure(bursts * IN_FLIGHT, elapsed, lat)


def client_bursts(endpoint: str, count: int, batch: bool = True) -> Figure:
    """AsyncClient reading in bursts: ``asyncio.gather`` of IN_FLIGHT reads, then the next
    (with ``batch``: one sum read per burst; without: IN_FLIGHT frames)."""
    return asyncio.run(_client_bursts(endpoint, count, batch))


async def _client_read_many(endpoint: str, count: int) -> tuple[Figure, int]:
    async with AsyncClient(endpoint) as c:
        names = [o.name for o in await c.browse() if o.access != "w"][:100]
        await c.read_many(names)  # handles acquired once
        lat = []
        start = time.perf_counter()
        for _ in range(count):
            t0 = time.perf_counter()
            await c.read_many(names)
            lat.append(time.perf_counter() - t0)
        elapsed = time.perf_counter() - start
    return figure(count, elapsed, lat), len(names)


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark and print the table."""
    parser = argparse.ArgumentParser(prog="python -m bench", description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--count", type=int, default=20000, help="reads per measurement")
    parser.add_argument("--part", choices=("all", "dispatch", "client", "ads", "kernel",
                                           "jitter", "virtual", "lookahead", "fairness", "cli",
                                           "web", "idle", "short-blocks", "opcua"),
                        default="all",
                        help="dispatch: request dispatch (ZeroMQ); client: AsyncClient "
                        "batching against the raw echo, wall and CPU; ads: pyads over AMS/TCP; "
                        "kernel: decoder, interpolator, planner; jitter: the realtime cycle "
                        "under load; virtual: whole-service virtual time speed; lookahead: "
                        "machining time against the optimum; fairness: reads while the "
                        "notification limit is used up; cli: cnc's start to exit; web: "
                        "cnc-web's live values and their cost; idle: an idle service's CPU "
                        "and its kernel's idle cycle; short-blocks: the spiral and the CAM "
                        "finishing program on the virtual clock (also in virtual); opcua: OPC "
                        "UA reads against asyncua's static server, start-up cold and warm, data "
                        "changes of 1 000 items, the cycle with 10 sessions")
    parser.add_argument("--jitter-s", type=float, default=20.0,
                        help="seconds of load per jitter run (issue 22 asks 60)")
    parser.add_argument("--idle-s", type=float, default=15.0,
                        help="seconds of an idle service per idle run")
    args = parser.parse_args(argv)
    if args.part in ("all", "dispatch"):
        dispatch(args)
    if args.part in ("all", "client"):
        from . import client_bench

        client_bench.main(args.runs, args.count * 2)
    if args.part in ("all", "ads"):
        from . import ads_bench, ads_clients_bench

        ads_bench.main(args.runs, args.count // 4)
        ads_clients_bench.main()
    if args.part in ("all", "kernel"):
        kernel(args.runs)
    realtime_rows: list[str] = []  # the jitter part's rows of the virtual part's table
    if args.part in ("all", "jitter"):
        from . import jitter_bench

        realtime_rows = jitter_bench.main(min(args.runs, 3), args.jitter_s)
    if args.part in ("all", "virtual"):  # issue 37's table, every row in one
        from . import virtual_bench

        virtual_bench.print_table(virtual_bench.all_rows(min(args.runs, 3)),
                                  tuple(realtime_rows))
    if args.part == "short-blocks":
        from . import virtual_bench

        virtual_bench.print_table(virtual_bench.short_blocks(min(args.runs, 3)))
    if args.part in ("all", "fairness"):
        from . import fairness_bench

        fairness_bench.main(min(args.runs, 3), 2000)
    if args.part in ("all", "cli"):
        from . import cli_bench

        cli_bench.main(args.runs)

    if args.part in ("all", "opcua"):
        from . import opcua_bench

        opcua_bench.main(min(args.runs, 3))

    if args.part in ("all", "idle"):
        from . import idle_bench

        idle_bench.main(min(args.runs, 3), args.idle_s)

    if args.part in ("all", "web"):
        from . import web_bench

        web_bench.main(min(args.runs, 3), min(args.jitter_s, 10.0))
    if args.part in ("all", "lookahead"):
        from . import lookahead_bench

        print("\nlook-ahead: ch1.program_time / time-optimal limit (virtual clock)")
        return lookahead_bench.main(["--plot", "lookahead-spiral.png"])
    return 0


def kernel(runs: int) -> None:
    """Decoder, interpolator and planner figures, each against its reference of the run."""
    from . import check_bench, decoder_bench, kernel_bench, planner_bench

    print("\nkernel benchmarks (in-process, virtual clock)", file=sys.stderr)
    dec = decoder_bench.measure(runs=runs)
    chk = check_bench.measure(runs=min(runs, 3))
    ipo = kernel_bench.measure(runs=min(runs, 3))
    trafo = kernel_bench.measure_trafo(runs=min(runs, 3))
    plan = planner_bench.measure(runs=min(runs, 3))
    print(f"\n{'measurement':52} {'value':>12} {'ratio':>7}  target")
    print(f"{'decoder, 200,000 lines (lines/s)':52} {dec['decoder_lines_s']:12,.0f} "
          f"{dec['ratio']:7.2f}  >= 0.5 of str.split: "
          f"{'met' if dec['ratio'] >= 0.5 else 'NOT met'}")
    print(f"{'  reference: str.split tokenizer (lines/s)':52} {dec['split_lines_s']:12,.0f}")
    print(f"{'syntax check, 200,000 lines (lines/s)':52} {chk['check_lines_s']:12,.0f} "
          f"{chk['ratio']:7.2f}  >= 0.5 of str.split: "
          f"{'met' if chk['ratio'] >= 0.5 else 'NOT met'}")
    print(f"{'interpolator, 3-axis program (simulated s / wall s)':52} "
          f"{ipo['sim_per_wall']:12.1f} {'':7}  >= 50: "
          f"{'met' if ipo['sim_per_wall'] >= 50 else 'NOT met'}")
    for unit in ("cycle", "block"):
        label = f"#TRAFO ON, 5-axis A/C lines (us per {unit})"
        print(f"{label:52} {trafo[f'trafo_us_per_{unit}']:12.2f} "
              f"{trafo[f'{unit}_ratio']:7.2f}  of the same lines without #TRAFO "
              f"({trafo[f'plain_us_per_{unit}']:.2f} us)")
    for name, label in (("spiral", "spiral 10,000 x 0.05 mm F6000"),
                        ("pocket", "pocket, 90 deg corners")):
        ratio = plan[f"{name}_ratio"]
        print(f"{'planner ' + label + ' (machining s)':52} {plan[name + '_time_s']:12.3f} "
              f"{ratio:7.4f}  <= 1.01 of optimal: {'met' if ratio <= 1.01 else 'NOT met'}")
    print(f"\ndecoder: median of {runs} paired runs; syntax check (kernel, START to READY), "
          "interpolator and planner: median of "
          f"{min(runs, 3)} runs; planner ratio = streamed 120-block look-ahead / whole program "
          "planned at once (same model)")


def dispatch(args: argparse.Namespace) -> None:
    """Request dispatch against the raw ZeroMQ echo."""

    ctx = mp.get_context("spawn")
    ready = ctx.Event()
    port_queue = ctx.Queue()
    echo = ctx.Process(target=serve_echo, args=(port_queue, ready), daemon=True)
    echo.start()
    echo_endpoint = port_queue.get(timeout=20)

    with tempfile.TemporaryDirectory() as tmp:
        machine = Path(tmp) / "bench.toml"
        machine.write_text(BENCH_MACHINE)
        service = start_service("--clock", "realtime", "--config", str(machine))
    try:
        keys = ("raw_seq", "raw_pipe", "seq", "flight", "bursts", "flight_plain",
                "bursts_plain", "echo_flight", "echo_bursts", "many")
        runs: dict[str, list[Figure]] = {k: [] for k in keys}
        n_objects = 0
        ratios: dict[str, list[float]] = {k: [] for k in keys[2:]}
        for run in range(args.runs):
            raw_seq = raw_sequential(echo_endpoint, args.count // 4)
            seq = client_sequential(service.endpoint, args.count // 4)
            raw_pipe = raw_pipelined(echo_endpoint, args.count * 2)
            flight = client_in_flight(service.endpoint, args.count * 2)
            bursts = client_bursts(service.endpoint, args.count * 2)
            flight_plain = client_in_flight(service.endpoint, args.count * 2, batch=False)
            bursts_plain = client_bursts(service.endpoint, args.count * 2, batch=False)
            # the client alone: the same reads answered by the raw echo (which answers
            # every frame as one read: no sum commands)
            echo_flight = client_in_flight(echo_endpoint, args.count * 2, batch=False)
            echo_bursts = client_bursts(echo_endpoint, args.count * 2, batch=False)
            many, n_objects = asyncio.run(_client_read_many(service.endpoint, args.count // 20))
            for key, fig_, base in (("raw_seq", raw_seq, None), ("seq", seq, raw_seq),
                                    ("raw_pipe", raw_pipe, None), ("flight", flight, raw_pipe),
                                    ("bursts", bursts, raw_pipe),
                                    ("flight_plain", flight_plain, raw_pipe),
                                    ("bursts_plain", bursts_plain, raw_pipe),
                                    ("echo_flight", echo_flight, raw_pipe),
                                    ("echo_bursts", echo_bursts, raw_pipe),
                                    ("many", many, raw_seq)):
                runs[key].append(fig_)
                if base is not None:
                    ratios[key].append(fig_.reads_s / base.reads_s)
            print(f"run {run + 1}/{args.runs}: sequential {ratios['seq'][-1]:.2f}, "
                  f"64 in flight {ratios['flight'][-1]:.2f} (bursts {ratios['bursts'][-1]:.2f}) "
                  "of the raw echo", file=sys.stderr)
        with Client(service.endpoint) as c:
            overruns = c.read_many(
                ["cnc_cycle_overruns_r", "cnc_cycle_jitter_max_r", "cnc_tick_counter_r"]
            )
    finally:
        service.stop()
        echo.terminate()

    fig = {k: median_figure(v) for k, v in runs.items()}
    ratio = {k: statistics.median(v) for k, v in ratios.items()} | {"raw_seq": 1.0, "raw_pipe": 1.0}
    _report(fig, ratio, n_objects, args.runs, overruns)


def _report(
    fig: dict[str, Figure], ratios: dict[str, float], n_objects: int, runs: int, kernel: dict
) -> None:
    rows = [
        ("raw echo, sequential (baseline)", "raw_seq", None),
        ("raw echo, 64 in flight (baseline)", "raw_pipe", None),
        ("Client.read_address, sequential", "seq", 0.6),
        ("AsyncClient, 64 reads in flight", "flight", 0.8),
        ("AsyncClient, bursts of 64 (gather)", "bursts", 0.8),
        ("  the same, batch=False: window", "flight_plain", None),
        ("  the same, batch=False: bursts", "bursts_plain", None),
        ("  the client alone (raw echo): window", "echo_flight", None),
        ("  the client alone (raw echo): bursts", "echo_bursts", None),
        (f"AsyncClient.read_many({n_objects}) calls", "many", None),
    ]
    print(f"\nmedian of {runs} runs; ratio: median of the per-run ratios to the raw echo "
          "(read_many: calls/s to sequential round trips/s)\n")
    print(f"{'measurement':38} {'reads/s':>10} {'ratio':>6} {'median us':>10} {'p99 us':>9}  target")
    for label, key, target in rows:
        f, ratio = fig[key], ratios[key]
        verdict = "" if target is None else (f">= {target}: " + ("met" if ratio >= target else "NOT met"))
        print(f"{label:38} {f.reads_s:10.0f} {ratio:6.2f} {f.median_us:10.1f} {f.p99_us:9.1f}  {verdict}")
    many = fig["many"]
    print(f"\nread_many: {many.reads_s * n_objects:,.0f} objects/s "
          f"({n_objects} objects per sum read)")
    print(f"kernel during the run: {kernel['cnc_tick_counter_r']} cycles, "
          f"{kernel['cnc_cycle_overruns_r']} overruns, "
          f"max jitter {kernel['cnc_cycle_jitter_max_r']} us")


if __name__ == "__main__":
    sys.exit(main())

