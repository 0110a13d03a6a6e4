"""Equality stays proved (issue 37): generated programs, two clocks, two module sets.

``test_event_speed_clock.py`` proves the event-speed clock against stepping on programs
of long blocks and on runs of short blocks. Here the two kinds are one program
(``nc_strategies.mixed_programs``: CAM-like runs of 0.01-0.1 mm lines and short arcs
between long lines, half circles, dwells and M functions, look-ahead on and off), with
the observer's subscriptions and the client writes of that test: every observed value
and every block change cycle bit for bit.

And the compiled hot path (``tools/build_native.py``) against the pure-Python one: the
same generated program, periods and writes run in two worker processes
(``tests.support.path_worker``), one with ``CNC_NATIVE=0``, on the stepping or the
event-speed clock; every published cycle's values must be the same ``repr`` (floats to
the last bit). ``test_native_path.py`` checks three fixed programs the same way.

A few examples by default (the same ones each time); ``--soak`` (``make soak``) or
``CNC_SOAK=1`` draws many new ones.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cnc_objects import _native
from cnc_objects.service.kernel.channel_mode import ChannelState
from tests.reliability import scale
from tests.support.event_speed import assert_same
from tests.support.nc_strategies import PERIODS, Write, mixed_programs, scripts, to_commands

ROOT = Path(__file__).resolve().parents[3]
WORKER_TIMEOUT_S = 300.0


def _settings(quick: int, soak: int) -> settings:
    """``quick`` derandomized examples, or ``soak`` random ones under the soak scale."""
    many = scale.soak()
    return settings(max_examples=soak if many else quick, deadline=None, derandomize=not many,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


def test_mixed_short_block_programs_are_cycle_exact_against_stepping() -> None:
    """Short-block runs inside ordinary programs, observed at generated periods, with
    feed override and feedhold writes: the event clock's every observed value is
    stepping's (20 examples; soak: 300)."""

    @_settings(quick=20, soak=300)
    @given(text=mixed_programs(), periods=PERIODS, writes=scripts())
    def check(text: str, periods: tuple[int, ...], writes: list[Write]) -> None:
        assert_same(text, periods, to_commands(writes))

    check()


# ------------------------------------------------------------- compiled against pure


class Worker:
    """One ``path_worker`` process (pure or compiled modules)."""

    def __init__(self, native: bool) -> None:
        env = dict(os.environ, CNC_NATIVE="1" if native else "0")
        self.process = subprocess.Popen(
            [sys.executable, "-m", "tests.support.path_worker"], cwd=ROOT, env=env,
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        assert self.process.stdout is not None
        self.kind = self.process.stdout.readline().strip()

    def run(self, job: dict[str, Any]) -> dict[str, Any]:
        """The worker's reply to one job."""
        assert self.process.stdin is not None and self.process.stdout is not None
        self.process.stdin.write(json.dumps(job) + "\n")
        self.process.stdin.flush()
        line = self.process.stdout.readline()
        assert line, f"the {self.kind} worker ended (exit code {self.process.poll()})"
        reply: dict[str, Any] = json.loads(line)
        assert "error" not in reply, f"the {self.kind} worker failed:\n{reply['error']}"
        return reply

    def close(self) -> None:
        """End the worker (stdin closed: it returns) and wait for it."""
        assert self.process.stdin is not None
        self.process.stdin.close()
        self.process.wait(timeout=WORKER_TIMEOUT_S)


@pytest.fixture(scope="module")
def workers() -> Iterator[tuple[Worker, Worker]]:
    """A compiled and a pure worker; skipped where the hot path is not compiled."""
    finder = _native.NativeFinder(_native.load_manifest() or {})
    if not finder.modules or not finder.active:
        pytest.skip("the hot path is not compiled here (no compiler, or sources changed "
                    "since the build): tools/build_native.py")
    compiled, pure = Worker(native=True), Worker(native=False)
    try:
        assert (compiled.kind, pure.kind) == ("compiled", "pure")
        yield compiled, pure
    finally:
        compiled.close()
        pure.close()


def test_compiled_path_equals_pure_python_on_generated_programs(
        workers: tuple[Worker, Worker]) -> None:
    """Generated mixed programs, on the stepping or the event-speed clock, with periods
    and writes: every published cycle is the same compiled and pure (15 examples;
    soak: 200)."""
    compiled, pure = workers

    @_settings(quick=15, soak=200)
    @given(text=mixed_programs(), event_speed=st.booleans(), periods=PERIODS,
           writes=scripts())
    def check(text: str, event_speed: bool, periods: tuple[int, ...],
              writes: list[Write]) -> None:
        job = {"text": text, "event_speed": event_speed, "periods": list(periods),
               "writes": writes}
        a, b = compiled.run(job), pure.run(job)
        assert a["end"] == b["end"], "the program ended at another cycle compiled"
        assert b["state"] == ChannelState.READY, "the generated program did not run to its end"
        assert len(a["cycles"]) > 1
        for (cycle_a, values_a), (cycle_b, values_b) in zip(a["cycles"], b["cycles"],
                                                             strict=True):
            assert cycle_a == cycle_b, f"published cycle {cycle_a} compiled, {cycle_b} pure"
            assert values_a == values_b, (
                f"cycle {cycle_a} differs:\ncompiled: {values_a}\npure:     {values_b}")

    check()
