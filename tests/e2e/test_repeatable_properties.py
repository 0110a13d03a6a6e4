"""Equality stays proved over the wire (issue 37): generated programs, real subscriptions.

Two properties over generated programs (``nc_strategies.mixed_programs``: runs of short
blocks between long lines, arcs, dwells and M functions), each on real services over
ZeroMQ, sampled by the service's notification hub:

- *Traces that repeat*: with ``--samples repeatable`` the same program and generated
  subscriptions (objects, cycle times, on change or cyclic) give the same trace, cycle
  for cycle and bit for bit, on ``--clock virtual`` (event speed: bulk between the due
  cycles), ``virtual-step`` and ``step`` (``cnc_objects.testing.trace``).
- *Subscriptions during bulk* (the default ``latest`` samples, ``--clock virtual``):
  every sample a client receives is a value of the cycle it says it is from (a due
  cycle of its subscription), the same as stepping's at that cycle of the run. The
  kernel time and the program time are subscribed at the same cycle time: samples of
  one cycle share their timestamp, so each sample is paired with its cycle's kernel
  time, and the program time places that cycle in the run. The reference is the
  ``virtual-step`` repeatable trace of every cycle.

A few examples by default (the same ones each time); ``--soak`` (``make soak``) or
``CNC_SOAK=1`` draws many new ones.
"""

from __future__ import annotations

import asyncio
import contextlib
from collections import defaultdict
from datetime import datetime
from pathlib import Path
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cnc_objects.clients import AsyncClient
from cnc_objects.protocol.values import ChannelState
from cnc_objects.testing import serving
from cnc_objects.testing.trace import TraceRecorder, TraceRow
from tests.reliability import scale
from tests.support.nc_strategies import mixed_programs

CLOCKS = ("virtual", "virtual-step", "step")
#: What a client watches of a run: positions (increments and mm), velocities, distances,
#: block, line, state, coolant, spindle, look-ahead fill, program time.
OBJECTS = (
    "ch1.ax1.command_position_acs", "ch1.ax2.command_position_acs",
    "ch1.ax3.command_position_acs", "ch1.ax1.command_position_pcs",
    "ch1.ax2.distance_to_go_pcs", "ch1.actual_path_velocity", "ch1.programmed_path_velocity",
    "ch1.remaining_path_in_block", "ch1.dist_prog_start", "ch1.actual_block_number",
    "ch1.actual_block_count", "ch1.mc_active_line_r", "ch1.mc_active_state_r",
    "ch1.mc_coolant_state_r", "ch1.mc_spindle_active_rev_r", "ch1.lookahead_blocks",
    "ch1.program_time",
)
#: (names, cycle_ms, on_change) of one ``TraceRecorder.watch``
WatchSpec = tuple[tuple[str, ...], int, bool]
TIMEOUT_S = 60.0


def _settings(quick: int, soak: int) -> settings:
    many = scale.soak()
    return settings(max_examples=soak if many else quick, deadline=None, derandomize=not many,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


@st.composite
def watch_specs(draw: st.DrawFn) -> list[WatchSpec]:
    """1-4 watches of distinct objects, each every cycle (0) or every 1-20 ms, cyclic or
    on change."""
    names = draw(st.lists(st.sampled_from(OBJECTS), min_size=1, max_size=8, unique=True))
    cuts = sorted(draw(st.sets(st.integers(1, len(names) - 1), max_size=3))) if len(
        names) > 1 else []
    groups = [names[a:b] for a, b in zip([0, *cuts], [*cuts, len(names)], strict=True)]
    return [(tuple(group), draw(st.sampled_from([0, 1, 2, 3, 5, 10, 20])), draw(st.booleans()))
            for group in groups]


def repeatable_trace(clock: str, program: Path, watches: list[WatchSpec]) -> list[TraceRow]:
    """The trace of ``program`` on a fresh service on ``clock`` with repeatable samples."""
    with serving("--clock", clock, "--samples", "repeatable") as service:
        recorder = TraceRecorder(service.endpoint, stepping=clock == "step")
        for names, cycle_ms, on_change in watches:
            recorder.watch(names, cycle_ms=cycle_ms, on_change=on_change)
        return recorder.run(program, timeout_s=TIMEOUT_S)


def test_repeatable_traces_of_generated_programs_are_the_same_on_every_clock(
        tmp_path: Path) -> None:
    """Generated programs and subscriptions: ``virtual``, ``virtual-step`` and ``step``
    give the same rows (6 examples, 18 services; soak: 40)."""
    program = tmp_path / "generated.nc"

    @_settings(quick=6, soak=40)
    @given(text=mixed_programs(max_pieces=4), watches=watch_specs())
    def check(text: str, watches: list[WatchSpec]) -> None:
        program.write_text(text)
        traces = {clock: repeatable_trace(clock, program, watches) for clock in CLOCKS}
        reference = traces["virtual-step"]
        if not all(on_change for _, _, on_change in watches):  # the run is in it
            assert reference[-1].kernel_ns > reference[0].kernel_ns
        for clock in ("virtual", "step"):
            _assert_same_rows(traces[clock], reference, clock)

    check()


def _assert_same_rows(rows: list[TraceRow], reference: list[TraceRow], clock: str) -> None:
    """The first differing row, named, if any; then the lengths."""
    for k, (row, expected) in enumerate(zip(rows, reference, strict=False)):
        assert row == expected, f"row {k} on {clock}: {row} != virtual-step's {expected}"
    assert len(rows) == len(reference), (
        f"{len(rows)} rows on {clock}, {len(reference)} on virtual-step")


# ------------------------------------------------------------ latest samples, in bulk

#: Subscribed beside the watched objects, at the watch's cycle time: which cycle a
#: sample is of (kernel time) and where that cycle lies in the run (program time).
KERNEL_TIME = "cnc_kernel_time_r"
PROGRAM_TIME = "ch1.program_time"


@st.composite
def latest_watches(draw: st.DrawFn) -> tuple[int, list[tuple[str, bool]]]:
    """A cycle time of 5-50 ms (cycles between two due ones run in bulk) and 1-6
    objects, each cyclic or on change."""
    names = draw(st.lists(st.sampled_from([n for n in OBJECTS if n != PROGRAM_TIME]),
                          min_size=1, max_size=6, unique=True))
    return draw(st.sampled_from([5, 10, 20, 50])), [(n, draw(st.booleans())) for n in names]


async def latest_samples(endpoint: str, program: str, cycle_ms: int,
                         watched: list[tuple[str, bool]]) -> tuple[list[Any], int]:
    """Subscribe (default samples), run ``program`` to its end and take the samples
    until one of the kernel time at or after the end has come; every sample, and the
    cycle time in ns."""
    samples: list[Any] = []
    async with AsyncClient(endpoint, timeout_s=TIMEOUT_S) as client:
        cycle_ns = int(await client.read("cnc_cycle_time_r")) * 1000
        end_seen = asyncio.Event()
        end_ns = [-1]

        async def follow(name: str, on_change: bool) -> None:
            stream = client.subscribe(name, on_change=on_change, cycle_ms=cycle_ms)
            async with contextlib.aclosing(stream):
                async for sample in stream:
                    samples.append(sample)
                    if name == KERNEL_TIME and 0 <= end_ns[0] <= round(sample.value * 1e9):
                        end_seen.set()

        subscriptions = [(KERNEL_TIME, False), (PROGRAM_TIME, False), *watched]
        tasks = [asyncio.create_task(follow(n, c)) for n, c in subscriptions]
        try:
            async with asyncio.timeout(TIMEOUT_S):
                await client.run_program(program)
                await client.wait_program()
                assert await client.read("ch1.mc_active_state_r") == ChannelState.READY
                end_ns[0] = round(await client.read(KERNEL_TIME) * 1e9)
                await end_seen.wait()
        finally:
            for task in tasks:
                task.cancel()
            await asyncio.gather(*tasks, return_exceptions=True)
    return samples, cycle_ns


def test_latest_samples_during_bulk_are_values_of_their_cycles(tmp_path: Path) -> None:
    """Generated programs watched with the default samples on the event-speed clock:
    every sample received is stepping's value at the due cycle it is stamped with
    (8 examples; soak: 80)."""
    program = tmp_path / "generated.nc"

    @_settings(quick=8, soak=80)
    @given(text=mixed_programs(max_pieces=4), watch=latest_watches())
    def check(text: str, watch: tuple[int, list[tuple[str, bool]]]) -> None:
        cycle_ms, watched = watch
        program.write_text(text)
        names = [name for name, _ in watched]
        # the reference: every cycle of the run, stepped
        reference = repeatable_trace("virtual-step", program, [(
            (*names, PROGRAM_TIME), 0, False)])
        with serving("--clock", "virtual") as service:
            asyncio.run(_upload(service.endpoint, program))
            samples, cycle_ns = asyncio.run(latest_samples(
                service.endpoint, program.name, cycle_ms, watched))
        by_cycle = _by_cycle(reference, cycle_ns)
        compared = _compare(samples, by_cycle, cycle_ns, cycle_ms)
        if not all(on_change for _, on_change in watched) and max(by_cycle) * cycle_ns > (
                2 * cycle_ms * 1_000_000):  # a cyclic sample of a run of two cycle times
            assert compared > 0, "no sample fell into the run"

    check()


async def _upload(endpoint: str, program: Path) -> None:
    async with AsyncClient(endpoint, timeout_s=TIMEOUT_S) as client:
        await client.upload(program.name, program.read_bytes())


def _start_cycle(pairs: list[tuple[int, float]], cycle_ns: int) -> int:
    """The kernel cycle a run started at, from (kernel cycle, program time s) pairs: while
    the program runs, their difference is its start; before, the program time is 0, and
    after its end it stands while the kernel time goes on (a later start)."""
    starts = [cycle - round(program_s * 1e9 / cycle_ns) for cycle, program_s in pairs
              if program_s > 0]
    assert starts, "no sample of the program's run"
    return min(starts)


def _by_cycle(rows: list[TraceRow], cycle_ns: int) -> dict[int, dict[str, Any]]:
    """The rows of a trace of every cycle by cycle of the run (``_start_cycle``)."""
    start = _start_cycle([(r.kernel_ns // cycle_ns, r.value) for r in rows
                          if r.name == PROGRAM_TIME], cycle_ns)
    cycles: dict[int, dict[str, Any]] = defaultdict(dict)
    for row in rows:
        cycles[row.kernel_ns // cycle_ns - start][row.name] = row.value
    return cycles


def _compare(samples: list[Any], reference: dict[int, dict[str, Any]], cycle_ns: int,
             cycle_ms: int) -> int:
    """Check every sample of a cycle of the run against ``reference``; how many were."""
    by_stamp: dict[datetime, dict[str, list[Any]]] = defaultdict(lambda: defaultdict(list))
    firsts = set()  # stamps of a first sample: sent at once, of the cycle then, not a due one
    for sample in samples:
        by_stamp[sample.timestamp][sample.name].append(sample.value)
        if sample.sequence == 1:
            firsts.add(sample.timestamp)
    cycles: dict[datetime, int] = {}  # the kernel cycle of each stamp
    pairs = []
    for stamp, values in by_stamp.items():
        kernel, program = values.get(KERNEL_TIME), values.get(PROGRAM_TIME)
        if not kernel:
            continue  # its kernel time was not sampled (dropped, or not due)
        assert len(kernel) == 1, f"one timestamp, several cycles: {kernel}"
        cycles[stamp] = round(kernel[0] * 1e9 / cycle_ns)
        assert stamp in firsts or cycles[stamp] * cycle_ns % (cycle_ms * 1_000_000) == 0, (
            f"kernel time {kernel[0]} s is not a due cycle of {cycle_ms} ms")
        if program:
            pairs.append((cycles[stamp], program[0]))
    start = _start_cycle(pairs, cycle_ns)
    last = max(reference)
    compared = 0
    for stamp, values in by_stamp.items():
        if stamp not in cycles or not 0 < cycles[stamp] - start <= last:
            # of no known cycle, or of one before or after the run (the reference's
            # cycle 0 is its kernel time at rest, where the program was selected later)
            continue
        cycle = cycles[stamp] - start
        for name, sampled in values.items():
            if name in (KERNEL_TIME, PROGRAM_TIME):
                continue
            assert len(sampled) == 1, f"{name}: several samples of one cycle: {sampled}"
            expected = reference[cycle][name]
            assert sampled[0] == expected, (
                f"{name} at cycle {cycle} of the run (stamped {stamp}): {sampled[0]!r}, "
                f"stepping: {expected!r}")
            compared += 1
    return compared
