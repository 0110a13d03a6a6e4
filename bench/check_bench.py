"""Syntax check throughput against the same ``str.split`` tokenizer as the decoder bench.

``python -m bench.check_bench [--lines N] [--runs R]``

The real kernel in-process on the virtual clock checks the generated program of the
decoder benchmark (``decoder_bench.generate_program``) with SYNCHK | MACHINE_LOCK: the
time from START to READY covers the decoder's check mode, the software-limit check of
every end point and arc, the SDA thread's hand-over and the GEO cycles that show the
progress. Each run times the reference tokenizer on the same text first (paired runs);
the figures are medians, the ratio is the median of the per-run ratios.
Target: check lines/s >= 0.5 x tokenizer lines/s.
"""

from __future__ import annotations

import argparse
import gc
import statistics
import sys
import time

from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.commands import SetExecutionMode
from tests.support.kernel import KernelHarness

from .decoder_bench import generate_program, split_tokenizer

SYNCHK_MACHINE_LOCK = 0x48


def measure(lines: int = 200_000, runs: int = 5) -> dict:
    """Paired runs; medians of lines/s and of the per-run ratio check/tokenizer."""
    text = generate_program(lines)
    count = text.count("\n")
    split_rates, check_rates, ratios = [], [], []
    with KernelHarness() as harness:
        assert harness.command(SetExecutionMode(0, SYNCHK_MACHINE_LOCK)) is None
        for _ in range(runs):
            gc.collect()
            started = time.perf_counter()
            split_tokenizer(text)
            split_s = time.perf_counter() - started
            gc.collect()
            started = time.perf_counter()
            run = harness.run(text, name="bench.nc", timeout_s=600)
            check_s = time.perf_counter() - started
            channel = run.channel
            assert channel.state == ChannelState.READY and channel.errors.count == 0, (
                [str(e) for e in channel.errors.entries])
            split_rates.append(count / split_s)
            check_rates.append(count / check_s)
            ratios.append(split_s / check_s)
    return {
        "split_lines_s": statistics.median(split_rates),
        "check_lines_s": statistics.median(check_rates),
        "ratio": statistics.median(ratios),
        "ratios": ratios,
    }


def main(argv: list[str] | None = None) -> int:
    """Print the figures of one measurement."""
    parser = argparse.ArgumentParser(prog="python -m bench.check_bench",
                                     description=__doc__.split("\n")[0])
    parser.add_argument("--lines", type=int, default=200_000)
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args(argv)
    result = measure(args.lines, args.runs)
    print(f"split tokenizer: {result['split_lines_s']:12,.0f} lines/s")
    print(f"syntax check:    {result['check_lines_s']:12,.0f} lines/s")
    print(f"ratio (median of runs): {result['ratio']:.2f}  (target >= 0.5) "
          f"runs: {', '.join(f'{r:.2f}' for r in result['ratios'])}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
