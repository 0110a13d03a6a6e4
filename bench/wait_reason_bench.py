"""What the wait reason (``ch<c>.mc_wait_reason_r``) costs the GEO cycle.

Two figures, both by CPU time so that other load on the machine matters less:

* per call: ``ChannelRunner._wait_reason()`` and a whole ``ChannelRunner.cycle()`` on a
  cruising path, the kernel thread stopped (ADS STOP) so nothing else runs (timeit,
  best of 5);
* the ``kernel_bench`` program, simulated seconds per CPU second, run alternately with
  the reason computed and with it replaced by a constant (the cost removed), so that
  both see the same machine moments.

    python -m bench.wait_reason_bench [--pairs N]
"""

from __future__ import annotations

import argparse
import statistics
import time
import timeit
from collections.abc import Callable

from cnc_objects.service.kernel.channel_run import ChannelRunner
from cnc_objects.service.kernel.kernel import Control, ControlCommand
from tests.support.kernel import KernelHarness

from .kernel_bench import three_axis_program

CALLS = 100_000


def per_call_us() -> dict[str, float]:
    """Best-of-5 microseconds per call of the reason and of a whole runner cycle."""
    with KernelHarness() as h:
        h.start("G1 X1000 F1\nM30\n")  # 1000 mm at 1 mm/min: cruising throughout
        h.wait_for(lambda s: s.channels[0].path.path_velocity_mm_s > 0)
        assert h.command(ControlCommand(Control.STOP)) is None
        runner = h.kernel.state.runners[0]
        assert isinstance(runner, ChannelRunner)
        clock = [0.0]

        def cycle() -> None:
            clock[0] += 0.001
            runner.cycle(clock[0])

        calls: dict[str, Callable[[], object]] = {
            "wait_reason_us": runner._wait_reason, "runner_cycle_us": cycle}
        result = {name: min(timeit.repeat(fn, number=CALLS, repeat=5)) / CALLS * 1e6
                  for name, fn in calls.items()}
        h.command(ControlCommand(Control.RUN))
    return result


def with_and_without(pairs: int) -> dict[str, list[float]]:
    """Simulated s per CPU s of the kernel bench program, with and without the reason."""
    real = ChannelRunner._wait_reason
    text = three_axis_program()
    runs: dict[str, list[float]] = {"without": [], "with": []}
    try:
        with KernelHarness() as h:
            for _ in range(pairs):
                for label in runs:
                    ChannelRunner._wait_reason = (  # type: ignore[method-assign]
                        real if label == "with" else lambda self: 0)
                    h.mdi("G90 G0 X0 Y0 Z0")
                    started = time.process_time()
                    run = h.run(text, name="bench.nc", timeout_s=600)
                    cpu_s = time.process_time() - started
                    runs[label].append(run.channel.path.program_time_s / cpu_s)
    finally:
        ChannelRunner._wait_reason = real  # type: ignore[method-assign]
    return runs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=6, help="runs with and without (6)")
    args = parser.parse_args()
    calls = per_call_us()
    print(f"wait reason: {calls['wait_reason_us']:.2f} us per call; whole runner cycle "
          f"{calls['runner_cycle_us']:.2f} us")
    for label, ratios in with_and_without(args.pairs).items():
        print(f"kernel bench {label} the reason: median {statistics.median(ratios):.2f} "
              f"simulated s per CPU s (runs {', '.join(f'{r:.1f}' for r in ratios)})")


if __name__ == "__main__":
    main()
