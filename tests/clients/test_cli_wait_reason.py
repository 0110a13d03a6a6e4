"""``cnc status`` and ``cnc run --wait`` say why the channel stands (its wait reason).

The real ``cnc`` process against a real service on the virtual clock: the programs stop
at M0/M1 (reasons that last until START), so nothing depends on how fast the machine is.
"""

from __future__ import annotations

import subprocess
import sys
import threading
from pathlib import Path

from cnc_objects.clients import Client
from cnc_objects.clients.cli.machine import EXIT_WAIT_TIMEOUT
from cnc_objects.protocol.wait_reasons import WaitReason
from cnc_objects.testing import ServiceProcess, wait_for
from tests.support.cli import ROOT, cnc, json_lines

M0_PROGRAM = "G1 X1 F6000\nM0\nG1 X2\nM30\n"
M0_LINE = "channel 1 waits: M0 programmed stop: waiting for START (PROGRAMMED_STOP)"


def test_status_shows_single_block_and_the_wait_reason(service: ServiceProcess) -> None:
    with Client(service.endpoint, timeout_s=10) as c:
        c.write("ch1.mc_command_single_block_w", True)
        c.upload("two.nc", b"G1 X1 F6000\nG1 X2\nM30\n")
        c.run_program("two.nc", 1)
        wait_for(c, "ch1.mc_wait_reason_r", int(WaitReason.SINGLE_BLOCK))
    human = cnc("status", endpoint=service.endpoint)
    assert human.returncode == 0, human.stderr
    assert ("single block on  waits: single block: waiting for START after a block "
            "(SINGLE_BLOCK)") in human.stdout
    [record] = json_lines(cnc("--json", "status", endpoint=service.endpoint))
    assert (record["single_block"], record["wait_reason"]) == (True, "SINGLE_BLOCK")
    assert record["wait_reason_text"] == "single block: waiting for START after a block"


def test_status_of_an_idle_channel_waits_for_nothing(service: ServiceProcess) -> None:
    human = cnc("status", endpoint=service.endpoint)
    assert "single block off  waits: -" in human.stdout, human.stdout


def test_run_wait_times_out_naming_the_reason(service: ServiceProcess, tmp_path: Path) -> None:
    program = tmp_path / "stop.nc"
    program.write_text(M0_PROGRAM)
    # 3 s: the stop is printed once it has held for WAIT_REASON_SETTLE_S (1 s)
    result = cnc("run", str(program), "--wait", "--wait-timeout", "3", endpoint=service.endpoint)
    assert result.returncode == EXIT_WAIT_TIMEOUT, result.stderr
    lines = result.stderr.splitlines()
    assert M0_LINE in lines  # the change, printed while waiting
    assert "M0 programmed stop: waiting for START (wait reason PROGRAMMED_STOP)" in (
        result.stderr.replace("\n", " ")), result.stderr


def test_run_wait_prints_each_change_of_the_reason(service: ServiceProcess,
                                                    tmp_path: Path) -> None:
    """The waiting ``cnc`` prints the M0 stop, and after START (from another client) the
    M1 stop, one line each, on stderr; after the second START it ends with the program
    (exit 0). Between the stops the program may run too briefly for a poll to see it go
    on: a "goes on" line may or may not come there."""
    program = tmp_path / "stops.nc"
    program.write_text("G1 X1 F6000\nM0\nG1 X2\nM1\nG1 X3\nM30\n")
    with Client(service.endpoint, timeout_s=10) as c:  # M1 stops only with its switch on
        c.write("ch1.mc_command_M01_stop_enable_w", True)
    argv = [sys.executable, "-c", "from cnc_objects.clients.cli import main; main()",
            "--endpoint", service.endpoint, "run", str(program), "--wait", "--wait-timeout", "60"]
    proc = subprocess.Popen(argv, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    watchdog = threading.Timer(90, proc.kill)  # a hung cnc ends the test, not the run
    watchdog.start()
    try:
        assert proc.stderr is not None
        lines = [proc.stderr.readline().rstrip("\n")]  # printed once cnc saw the stop
        assert lines == [M0_LINE]
        with Client(service.endpoint, timeout_s=10) as c:
            c.start(1)
            while not lines[-1].endswith("(OPTIONAL_STOP)") and lines[-1]:
                lines.append(proc.stderr.readline().rstrip("\n"))
            c.start(1)
        out, rest = proc.communicate(timeout=60)
    finally:
        watchdog.cancel()
        with Client(service.endpoint, timeout_s=10) as c:
            c.write("ch1.mc_command_M01_stop_enable_w", False)
    assert proc.returncode == 0, rest
    assert [line for line in lines if line != "channel 1 goes on"] == [
        M0_LINE, "channel 1 waits: M1 optional stop: waiting for START (OPTIONAL_STOP)"]
    assert "stops.nc finished" in out


def test_run_wait_leaves_out_reasons_of_a_moment(service: ServiceProcess,
                                                 tmp_path: Path) -> None:
    """A spindle ramp and a short dwell are waits of a moment (far below the second a
    reason must hold): the run prints its result and nothing on stderr."""
    program = tmp_path / "short.nc"
    program.write_text("S1000 M3\nG1 X1 F6000\nG4 X0.2\nM5\nM30\n")
    result = cnc("run", str(program), "--wait", endpoint=service.endpoint)
    assert result.returncode == 0, result.stderr
    assert result.stderr == "" and "short.nc finished" in result.stdout
