"""Each synchronisation kind's timing, cycle by cycle, played as the PLC over ADS (pyads).

A real cnc-service on the step clock (``--clock step``): no cycle runs until the test
writes ``cnc_cycle_step_w``; the write's reply comes after the granted cycle is
published, so the sum read that follows (one ``read_list_by_name``: cycle counter, X,
path velocity, used units and the units' number and state) shows exactly that cycle.
The test steps one cycle at a time, records every cycle, acknowledges at a cycle it
chooses, and asserts cycle numbers as tests/service/kernel/test_plc_functions.py does
in-process: when the function is output, where the path stands while it waits, and that
motion goes on in the first cycle after the acknowledge. The rule: the acknowledge,
written between cycles c and c + 1, is applied at once (read back at cycle c: nothing
pending, the path where it stood); commands are applied at the start of a cycle, before
the path's step, so cycle c + 1 already moves.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import pyads
import pytest

from cnc_objects.clients import AdsError, Client
from cnc_objects.testing import ServiceProcess, start_service
from tests.support.pyads_plc import plc_machine, pyads_service

LOCAL_NET_ID = "127.0.0.1.1.22"
STEP = "cnc_cycle_step_w"
CYCLE = "cnc_tick_counter_r"
X_POS = "ch1.ax1.command_position_acs"  # 0.1 um
VELOCITY = "ch1.actual_path_velocity"  # um/s
USED = "gpCh[0].used_units_std_sync_r"
UNIT = "gpCh[0].techno_unit_std_sync[{k}].{field}"
UNITS = 16
INCR = 10_000  # 0.1 um per mm
MAX_CYCLES = 5_000  # a program here takes about 500: more is a hang
WAIT_CYCLES = 50  # the PLC takes this many cycles to acknowledge
CONFIG = plc_machine({"10": "MOS", "11": "MVS_SVS", "12": "MVS_SNS", "13": "MNS_SNS"})
# G00 X0 first: every program runs from X0 upwards, whatever the one before left.
PROGRAM = "G00 X0\nG01 X10 F6000\nN20 G01 X20 M{m}\nN30 G01 X30\nM30\n"
NAMES = [CYCLE, X_POS, VELOCITY, USED] + [
    UNIT.format(k=k, field=f) for k in range(UNITS) for f in ("attribut_r.nr", "state_r")
]


@dataclass(frozen=True)
class Row:
    """One cycle as the PLC read it."""

    cycle: int
    x_mm: float
    velocity_um_s: float
    used: int
    listed: bool  # the test's M function is listed in a unit
    pending: bool  # ... and waits for the acknowledge
    unit: int | None  # its unit's index


@dataclass
class Plc:
    service: ServiceProcess
    plc: pyads.Connection  # 851

    def row(self, m: int) -> Row:
        """The current cycle, read in one ADS sum read."""
        values = self.plc.read_list_by_name(NAMES)
        unit = next((k for k in range(UNITS)
                     if values[UNIT.format(k=k, field="attribut_r.nr")] == m), None)
        pending = unit is not None and values[UNIT.format(k=unit, field="state_r")]
        return Row(values[CYCLE], values[X_POS] / INCR, values[VELOCITY], values[USED],
                   unit is not None, bool(pending), unit)

    def step(self, cycles: int = 1) -> None:
        self.plc.write_by_name(STEP, cycles, pyads.PLCTYPE_UDINT)


@pytest.fixture(scope="module")
def plc(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Plc]:
    with pyads_service(tmp_path_factory.mktemp("plc-cycles"), LOCAL_NET_ID, "--clock", "step",
                       config=CONFIG) as (service, (connection,)):
        yield Plc(service, connection)


class Run:
    """A program started on the step clock and every cycle since, one step at a time."""

    def __init__(self, plc: Plc, m: int) -> None:
        self.plc, self.m = plc, m
        with Client(plc.service.endpoint) as client:
            client.upload(f"m{m}.nc", PROGRAM.format(m=m).encode())
            client.run_program(f"m{m}.nc")  # applied at once: no cycle is granted
        self.rows = [plc.row(m)]

    @property
    def last(self) -> Row:
        return self.rows[-1]

    def step(self) -> Row:
        """One cycle: the read after the step's reply shows exactly the next cycle."""
        self.plc.step(1)
        row = self.plc.row(self.m)
        assert row.cycle == self.last.cycle + 1
        self.rows.append(row)
        return row

    def until(self, predicate: Callable[[Row], bool]) -> Row:
        for _ in range(MAX_CYCLES):
            if predicate(row := self.step()):
                return row
        raise AssertionError(f"no such cycle within {MAX_CYCLES}: last {self.last}")

    def before(self, row: Row) -> Row:
        return next(r for r in self.rows if r.cycle == row.cycle - 1)

    def acknowledge(self) -> Row:
        """Acknowledge as the PLC between two cycles; the write returns without a step
        and its effect is read back at the same cycle."""
        stood = self.last
        assert stood.unit is not None and stood.pending
        self.plc.plc.write_by_name(UNIT.format(k=stood.unit, field="command_w"), True)
        acked = self.plc.row(self.m)
        assert acked.cycle == stood.cycle  # no cycle passed for the write
        assert (acked.used, acked.pending, acked.x_mm) == (0, False, stood.x_mm)
        return acked

    def finish(self) -> None:
        self.until(lambda r: r.x_mm == 30.0 and r.velocity_um_s == 0.0)


def _passes(run: Run, row: Row, x_mm: float) -> bool:
    """The path passed ``x_mm`` (upwards) in cycle ``row``."""
    return run.before(row).x_mm < x_mm <= row.x_mm


def _waits(run: Run, stand_mm: float) -> Row:
    """The PLC takes WAIT_CYCLES cycles: the path stands at ``stand_mm`` all of them."""
    for _ in range(WAIT_CYCLES):
        row = run.step()
        assert (row.x_mm, row.velocity_um_s, row.pending) == (stand_mm, 0.0, True)
    return run.last


def _goes_on(run: Run, acked: Row, stand_mm: float) -> None:
    """Motion goes on in the first cycle after the acknowledge."""
    moved = run.step()
    assert moved.cycle == acked.cycle + 1
    assert moved.x_mm > stand_mm and moved.velocity_um_s > 0.0


def _acknowledged_after_waiting(run: Run, x_mm: float) -> None:
    """The path stands at ``x_mm`` while the PLC takes its cycles; the PLC acknowledges,
    the motion goes on in the next cycle, and the program runs to its end."""
    _waits(run, x_mm)
    acked = run.acknowledge()
    _goes_on(run, acked, x_mm)
    run.finish()


def test_mvs_svs_output_before_the_motion_which_waits_for_the_acknowledge(plc: Plc) -> None:
    run = Run(plc, 11)
    out = run.until(lambda r: r.listed)
    assert out.pending and out.used == 1
    assert out.x_mm == 10.0 and out.velocity_um_s == 0.0  # before N20's motion
    _acknowledged_after_waiting(run, 10.0)


def test_mvs_sns_output_before_the_motion_waited_for_at_the_block_end(plc: Plc) -> None:
    run = Run(plc, 12)
    out = run.until(lambda r: r.listed)
    assert out.pending and _passes(run, out, 10.0)  # output where N20's motion starts
    at_end = run.until(lambda r: r.x_mm == 20.0 and r.velocity_um_s == 0.0)
    moving_pending = [r for r in run.rows if out.cycle <= r.cycle < at_end.cycle]
    assert all(r.pending and 10.0 <= r.x_mm <= 20.0 for r in moving_pending)
    assert any(10.0 < r.x_mm < 20.0 for r in moving_pending)  # it ran while pending
    _acknowledged_after_waiting(run, 20.0)  # it stopped at the block end and waits there


def test_mns_sns_output_at_the_block_end_and_waited_for_there(plc: Plc) -> None:
    run = Run(plc, 13)
    out = run.until(lambda r: r.listed)
    assert out.pending and out.x_mm == 20.0 and out.velocity_um_s == 0.0
    assert run.before(out).x_mm <= 20.0  # not output before the path got to the end
    assert not any(r.listed for r in run.rows if r.x_mm < 20.0)
    _acknowledged_after_waiting(run, 20.0)


def test_mos_output_while_the_path_runs_on(plc: Plc) -> None:
    run = Run(plc, 10)
    out = run.until(lambda r: r.listed)
    assert not out.pending and out.used == 0  # output, nothing to acknowledge
    assert _passes(run, out, 10.0)  # at the start of N20's motion
    run.finish()
    assert not any(r.velocity_um_s == 0.0 for r in run.rows if 10.0 < r.x_mm < 30.0)


@pytest.mark.parametrize("cycles", [0, 100_001])  # nothing; over [limits] step_max_cycles
def test_a_step_out_of_range_is_refused_and_runs_no_cycle(plc: Plc, cycles: int) -> None:
    before = plc.plc.read_by_name(CYCLE)
    with pytest.raises(pyads.ADSError) as refused:
        plc.step(cycles)
    assert refused.value.err_code == 0x706  # DEVICE_INVALIDDATA
    with Client(plc.service.endpoint) as client, pytest.raises(AdsError) as told:
        client.write(STEP, cycles)
    assert told.value.code == 0x706
    assert f"grants 1 to 100000 cycles ([limits] step_max_cycles), not {cycles}" in str(
        told.value)
    assert plc.plc.read_by_name(CYCLE) == before


def test_a_step_runs_exactly_the_cycles_granted(plc: Plc) -> None:
    before = plc.plc.read_by_name(CYCLE)
    plc.step(1000)
    assert plc.plc.read_by_name(CYCLE) == before + 1000
    assert plc.plc.read_by_name("cnc_kernel_time_r") == pytest.approx((before + 1000) / 1000)


def test_a_step_under_another_clock_is_refused(tmp_path: Path) -> None:
    service = start_service("--clock", "virtual", program_dir=tmp_path / "programs")
    try:
        with Client(service.endpoint) as client, pytest.raises(AdsError) as refused:
            client.write(STEP, 1)
        assert refused.value.code == 0x707  # DEVICE_NOTREADY
        assert "only under --clock step" in str(refused.value)
    finally:
        assert service.stop() == 0, service.log_text
