"""The bench's cli part (``python -m bench --part cli``): ``cnc --help`` and ``cnc read``
from start to exit, against ``python -c pass`` measured in the same run.

The target of issue 29 is 0.25 s each on an idle 2-core machine; the tests run on a
machine shared with other work, so the bounds here are generous: the CPU time a start
uses, as a multiple of a bare interpreter's (the wall time is mostly waiting for a core
when the machine is loaded), and a wall time that only a start importing far more than it
needs would exceed. What a start may import is checked exactly in
tests/clients/test_cli_help.py."""

from __future__ import annotations

import pytest

from bench import cli_bench

HELP_CPU_RATIO_MAX = 9.0  # cnc --help: about 5x python -c pass (typer and the commands)
READ_CPU_RATIO_MAX = 14.0  # cnc read: about 8x (also zmq, msgpack, asyncio, one request)
WALL_S_MAX = 5.0  # a start's wall time, on a loaded machine


def test_cnc_starts_quickly() -> None:
    figures = cli_bench.measure(runs=5)
    python = figures["python"]
    for key, ratio_max in (("help", HELP_CPU_RATIO_MAX), ("read", READ_CPU_RATIO_MAX)):
        fig = figures[key]
        print(f"{cli_bench.LABELS[key]}: wall {fig.wall_s * 1e3:.0f} ms, CPU "
              f"{fig.cpu_s * 1e3:.0f} ms ({fig.cpu_s / python.cpu_s:.1f}x python -c pass)")
        assert fig.cpu_s < ratio_max * python.cpu_s, (key, fig, python)
        assert fig.wall_s < WALL_S_MAX, (key, fig)


def test_the_cli_part_prints_its_table(capsys: pytest.CaptureFixture[str]) -> None:
    cli_bench.main(runs=1)  # at least 5 runs, whatever is asked
    table = capsys.readouterr().out
    for label in cli_bench.LABELS.values():
        assert label in table
    assert table.count("< 0.25 s: ") == 2
