"""``cnc step``: grant cycles to a service on the step clock (``--clock step``).

Writes ``cnc_cycle_step_w`` = N; the service answers after the N-th cycle is published,
so the cycle counter read next is exactly that cycle (docs/kernel.md, How time advances).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import typer

from .. import names
from .app import Settings, command, emit

if TYPE_CHECKING:  # the client library is imported when a command connects (a quick --help)
    from ..blocking import Client

STEP_OBJECT = names.cnc_cycle_step_w


@command()
def step(
    ctx: typer.Context,
    cycles: int = typer.Argument(1, min=1, help="Cycles to run (1..[limits] step_max_cycles)."),
) -> None:
    """Run N kernel cycles on a service started with --clock step, then show the cycle
    counter and kernel time.

    Returns after the N-th cycle; a large N takes long (about 60 us per idle cycle), so
    give --timeout room. Under another clock the service refuses (ADS 0x707).
    """
    settings: Settings = ctx.obj

    def act(c: Client) -> dict[str, Any]:
        c.write(STEP_OBJECT, cycles)
        return {"cycles": cycles, "cycle": c.read(names.cnc_tick_counter_r),
                "kernel_time_s": c.read(names.cnc_kernel_time_r)}

    r = settings.call(act, f"step {cycles} cycles")
    emit(settings, r, f"cycle {r['cycle']}  kernel time {r['kernel_time_s']:.6f} s")
