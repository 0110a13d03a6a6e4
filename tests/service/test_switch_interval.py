"""The GIL switch interval of a running realtime service (issue 37).

Under SCHED_FIFO the interval is half a cycle: the cycle thread, once it has the GIL,
is taken off it by another thread less often inside its cycle (overruns 0.29 % -> 0.09 %
in the jitter bench, docs/kernel.md "What delays the realtime cycle"). Without real-time
priority it stays a quarter cycle. The service logs what it set.
"""

from __future__ import annotations

from pathlib import Path

from cnc_objects.service.kernel.realtime_priority import DEFAULT_RT_PRIORITY
from tests.support.realtime import fifo_permitted
from tests.support.service import serving


def test_a_realtime_service_under_sched_fifo_switches_the_gil_every_half_cycle(
        tmp_path: Path) -> None:
    config = tmp_path / "cycle.toml"
    config.write_text("cycle_ms = 2.0\n")
    granted = fifo_permitted(DEFAULT_RT_PRIORITY - 1)  # the service's threads' priority
    with serving("--clock", "realtime", "--config", str(config)) as service:
        line = service.wait_for_log(r"GIL switch interval \S+ ms")
        assert ("GIL switch interval 1 ms" if granted else "GIL switch interval 0.5 ms") in line


def test_without_real_time_priority_it_is_a_quarter_cycle() -> None:
    with serving("--clock", "realtime", "--rt-priority", "0") as service:
        line = service.wait_for_log(r"GIL switch interval \S+ ms")
        assert "GIL switch interval 0.25 ms" in line
