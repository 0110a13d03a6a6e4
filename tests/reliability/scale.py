"""How much each reliability test does: the quick scale of ``make test`` or the soak scale.

The soak scale is chosen by ``pytest tests/reliability --soak`` or by the environment
variable ``CNC_SOAK=1`` (which works from any directory, where ``--soak`` is known only
when pytest starts in ``tests/reliability``). Every count is a bound: the soak run ends
by itself.
"""

from __future__ import annotations

import os
from dataclasses import dataclass


@dataclass(frozen=True)
class Scale:
    """The counts of one scale; ``name`` says which one in the printed figures."""

    name: str
    wire_frames: int  # malformed frames sent to the ZeroMQ front end
    wire_batch: int  # frames between two health checks (a fresh client reads)
    nc_mutations: int  # mutated NC programs, each syntax-checked and run
    nc_cli_programs: int  # of those, how many also go through `cnc check` / `cnc run`
    load_clients: int  # concurrent clients of the load test
    load_rounds: int  # rounds per client: a handle-by-name read, a write, its read-back
    killed_clients: int  # client processes killed with SIGKILL with subscriptions open
    store_kills: int  # SIGTERMs during uploads (and as many during runs)
    restarts: int  # stop-and-start-again cycles on one endpoint
    broker_restarts: int  # MQTT broker stop/start cycles under the bridge
    output_write_loops: int  # MDI #MSG SAVE loops run to the output limit, clients reading
    long_line_resets: int  # RESETs during the syntax check of a 100 000-word line
    long_line_words: int  # the most words of a long line the NC fuzz generates
    flood_ads: int  # ADS connections of a partial-frame flood (each 1 MiB - 100 bytes)
    flood_zmq: int  # ZeroMQ connections of a partial-frame flood (each 2 MB - 100 bytes)
    half_sent_examples: int  # wire fuzz: floods of half-sent frames (hypothesis examples)
    fairness_reads: int  # reads timed under the full notification load


QUICK = Scale(
    "make test", wire_frames=10_000, wire_batch=500, nc_mutations=64, nc_cli_programs=3,
    load_clients=50, load_rounds=1_000, killed_clients=1, store_kills=3, restarts=3,
    broker_restarts=2, output_write_loops=2, long_line_resets=1, long_line_words=4_000,
    flood_ads=200, flood_zmq=150,
    half_sent_examples=8, fairness_reads=2_000,
)
SOAK = Scale(
    "make soak", wire_frames=100_000, wire_batch=500, nc_mutations=640, nc_cli_programs=12,
    load_clients=50, load_rounds=10_000, killed_clients=5, store_kills=20, restarts=20,
    broker_restarts=10, output_write_loops=10, long_line_resets=5, long_line_words=60_000,
    flood_ads=600, flood_zmq=400,
    half_sent_examples=60, fairness_reads=20_000,
)

soak_option = False  # set by conftest.py from --soak


def soak() -> bool:
    """True when the soak scale was asked for (``--soak`` or ``CNC_SOAK=1``)."""
    return soak_option or os.environ.get("CNC_SOAK", "") not in ("", "0")


def current() -> Scale:
    """The scale of this run."""
    return SOAK if soak() else QUICK
