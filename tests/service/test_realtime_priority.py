"""Real-time priority of the realtime clock's cycle thread (issue 30): SCHED_FIFO and
locked memory where the process is permitted, a warning and a normal thread where not.

Every case runs the real service. What a process of this machine is permitted is
probed first, in a child process that asks for the same things the service does; the
denial case drops the capabilities with ``setpriv`` (util-linux), which makes even root
unprivileged for SCHED_FIFO and mlockall (RLIMIT_RTPRIO 0, an RLIMIT_MEMLOCK below the
service's size)."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from cnc_objects.clients import Client
from cnc_objects.service.kernel.realtime_priority import DEFAULT_RT_PRIORITY, SchedPolicy
from tests.support.realtime import fifo_permitted
from tests.support.service import serving

GRANT_LOG = r"cycle thread under SCHED_\w+"
#: Without these capabilities (and with the default rlimits of 0 and 8 MiB) a process
#: may neither run SCHED_FIFO nor lock its memory.
DROP_PRIVILEGES = ("setpriv", "--bounding-set=-sys_nice,-ipc_lock",
                   "--inh-caps=-sys_nice,-ipc_lock")




def grant_objects(endpoint: str) -> dict[str, object]:
    with Client(endpoint) as c:
        return c.read_many(["cnc_cycle_sched_policy_r", "cnc_cycle_sched_priority_r",
                            "cnc_memory_locked_r"])


def test_the_cycle_thread_runs_sched_fifo_at_the_configured_priority(tmp_path: Path) -> None:
    config = tmp_path / "rt.toml"
    config.write_text("rt_priority = 7\n")
    granted = fifo_permitted(7)
    with serving("--clock", "realtime", "--config", str(config)) as service:
        line = service.wait_for_log(GRANT_LOG)
        figures = grant_objects(service.endpoint)
        assert figures["cnc_cycle_sched_policy_r"] == (
            SchedPolicy.FIFO if granted else SchedPolicy.OTHER), line
        assert figures["cnc_cycle_sched_priority_r"] == (7 if granted else 0)
        # the service's own threads one below, so that none holding the GIL is preempted
        # by another process (the event loop is the process's main thread)
        assert os.sched_getscheduler(service.process.pid) == (
            os.SCHED_FIFO if granted else os.SCHED_OTHER)
        if granted:
            assert "SCHED_FIFO priority 7" in line
            assert os.sched_getparam(service.process.pid).sched_priority == 6
            service.wait_for_log("service threads under SCHED_FIFO priority 6")
            # the same privilege (root) locks memory here: the log says both
            assert figures["cnc_memory_locked_r"] == ("memory locked" in line)
        assert len([ln for ln in service.log if "cycle thread under" in ln]) == 1  # once


def test_the_option_turns_it_off_and_wins_over_the_configuration(tmp_path: Path) -> None:
    config = tmp_path / "rt.toml"
    config.write_text("rt_priority = 7\n")
    with serving("--clock", "realtime", "--config", str(config), "--rt-priority", "0") as service:
        line = service.wait_for_log(GRANT_LOG)
        assert "real-time priority is off (--rt-priority 0)" in line
        assert os.sched_getscheduler(service.process.pid) == os.SCHED_OTHER
        assert not any("service threads under" in ln for ln in service.log)
        assert grant_objects(service.endpoint) == {
            "cnc_cycle_sched_policy_r": SchedPolicy.OTHER, "cnc_cycle_sched_priority_r": 0,
            "cnc_memory_locked_r": False}


@pytest.mark.skipif(shutil.which("setpriv") is None, reason="setpriv (util-linux) not installed")
def test_a_refusal_is_logged_and_the_service_goes_on() -> None:
    assert not fifo_permitted(DEFAULT_RT_PRIORITY, DROP_PRIVILEGES)  # the premise
    with serving("--clock", "realtime", wrapper=DROP_PRIVILEGES) as service:
        line = service.wait_for_log(GRANT_LOG)
        assert "WARNING" in line
        assert "SCHED_FIFO refused: Operation not permitted" in line
        assert "mlockall refused" in line
        assert "the service goes on without" in line
        service.wait_for_log("service threads under SCHED_OTHER")
        figures = grant_objects(service.endpoint)
        assert figures == {"cnc_cycle_sched_policy_r": SchedPolicy.OTHER,
                           "cnc_cycle_sched_priority_r": 0, "cnc_memory_locked_r": False}
        with Client(service.endpoint) as c:  # and the cycle runs
            ticks = c.read("cnc_tick_counter_r")
            c.write("cnc_cycle_stats_reset_w", True)  # a write needs a cycle to apply it
            assert c.read("cnc_tick_counter_r") != ticks


def test_the_virtual_clock_asks_for_nothing() -> None:
    with serving() as service:
        assert grant_objects(service.endpoint) == {
            "cnc_cycle_sched_policy_r": SchedPolicy.OTHER, "cnc_cycle_sched_priority_r": 0,
            "cnc_memory_locked_r": False}
        assert not any("cycle thread under" in ln for ln in service.log)


def test_a_priority_out_of_range_is_refused_at_start(tmp_path: Path) -> None:
    config = tmp_path / "rt.toml"
    config.write_text("rt_priority = 100\n")
    with pytest.raises(RuntimeError, match="rt_priority"):
        with serving("--clock", "realtime", "--config", str(config)):
            pass
