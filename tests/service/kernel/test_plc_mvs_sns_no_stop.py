"""MVS_SNS without a stop (issue 39): the block end is a stop only while the
acknowledge is outstanding.

ISG (tf5200 "Example with MVS_SNS", infosys.beckhoff.com/content/1033/tf5200_m_and_h_func/
285974155.html): "When the N40 block is executed, M25 is output and the motion is
continued. If the acknowledgement of M25 is not received in good time, the program
stops at the end of N40."

Hand calculation on the default machine (1 ms cycle, X 5000 mm/s^2): F6000 is 100 mm/s;
braking from 100 mm/s takes 100/5000 = 20 ms over 100^2 / (2 * 5000) = 1 mm. N20 runs
X10 -> X20 at 100 mm/s (the output is where it starts, X10): 10 mm take 100 cycles, the
braking for a stop at X20 would start at X19, 90 cycles after the output. The embedded
PLC acknowledges after the function's time (``prozess_zeit_default``):

* 30 ms: acknowledged 30 cycles after the output, at X13, 60 cycles before the braking
  would begin: the path passes X20 at 100 mm/s and never slows down before N30's end;
* 200 ms: the path stops at X20 (90 + 20 = 110 ms after the output) and stands there
  until the acknowledge 200 cycles after the output; it moves in the next cycle.
"""

from __future__ import annotations

from typing import Any

import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.state import Snapshot
from cnc_objects.service.machine_config import DEFAULT_MACHINE
from tests.support.kernel import KernelHarness
from tests.support.plc_recorder import KINDS, Recorder

PROGRAM = "G01 X10 F6000\nN20 G01 X20 M12\nN30 G01 X30\nM30\n"  # M12: MVS_SNS
FEED_MM_S = 6000.0 / 60.0  # the planned velocity through X20


def _config(time_us: int) -> Any:
    channels = [dict(c) for c in DEFAULT_MACHINE["channels"]]
    channels[0]["techno"] = {"m_synch": KINDS, "auto_acknowledge": True,
                             "prozess_zeit_default": time_us}
    return build_config({"channels": channels})


def _x(s: Snapshot) -> float:
    return s.channels[0].axes[0].position_mm


def _v(s: Snapshot) -> float:
    return s.channels[0].path.path_velocity_mm_s


def _units(s: Snapshot) -> Any:
    return s.channels[0].plc_functions.units


def _pending(s: Snapshot) -> bool:
    return s.channels[0].plc_functions.used_units > 0


def _run(time_us: int) -> tuple[list[Snapshot], Snapshot, Snapshot]:
    """Run the program; every cycle, the cycle of the output and of the acknowledge."""
    with KernelHarness(config=_config(time_us)) as h:
        rec = Recorder(h)
        assert h.run(PROGRAM).channel.state == ChannelState.READY
        out = rec.first(lambda s: bool(_units(s)))
        acked = rec.first(lambda s: _units(s) and not _pending(s))
        return list(rec.rows), out, acked


def test_an_early_acknowledge_runs_through_the_block_end_at_the_planned_speed() -> None:
    rows, out, acked = _run(30_000)
    assert acked.cycle - out.cycle == 30 and _x(acked) == pytest.approx(13.0, abs=0.15)
    passing = next(s for p, s in zip(rows, rows[1:], strict=False) if _x(p) < 20.0 <= _x(s))
    assert _v(passing) == pytest.approx(FEED_MM_S)  # not 0: no stop at N20's end
    # full speed from the output to N30's braking (X29): never slowed down at X20
    between = [s for s in rows if out.cycle <= s.cycle and _x(s) <= 29.0]
    assert min(_v(s) for s in between) == pytest.approx(FEED_MM_S)
    assert not any(_x(s) == 20.0 and _v(s) == 0.0 for s in rows)


def test_a_late_acknowledge_stops_the_path_at_the_block_end_until_it_comes() -> None:
    rows, out, acked = _run(200_000)
    assert acked.cycle - out.cycle == 200
    stop = next(s for s in rows if _x(s) == 20.0 and _v(s) == 0.0)
    assert stop.cycle - out.cycle == pytest.approx(110, abs=1)  # 90 cruise + 20 braking
    assert all(_x(s) == 20.0 and _v(s) == 0.0 for s in rows
               if stop.cycle <= s.cycle <= acked.cycle)
    assert next(s for s in rows if _x(s) > 20.0).cycle == acked.cycle + 1
