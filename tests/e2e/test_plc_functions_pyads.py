"""The PLC side of M functions, played with pyads over ADS (port 851, HLI symbols).

A real cnc-service on the virtual clock whose channel 1 lists M10..M13 with the four
synchronisation kinds and leaves the acknowledge to the PLC (``auto_acknowledge =
false``). The test is the PLC: it polls ``gpCh[0].used_units_std_sync_r``, reads the
unit, checks where the path stands, lets kernel time pass (the virtual clock runs
cycles back to back while the path waits) and acknowledges with
``techno_unit_std_sync[k].command_w``. The cycle-exact proofs of each kind are in
tests/service/kernel/test_plc_functions.py (every cycle recorded); here the claims are
about kernel time read over ADS: the path stood still for the cycles the PLC took.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import pyads
import pytest

from cnc_objects.clients import Client
from cnc_objects.testing import ServiceProcess
from tests.support.pyads_plc import plc_machine, pyads_service

LOCAL_NET_ID = "127.0.0.1.1.21"
WAIT_S = 20.0
UNIT = "gpCh[0].techno_unit_std_sync[{k}].{field}"
USED = "gpCh[0].used_units_std_sync_r"
X_POS = "ch1.ax1.command_position_acs"  # 0.1 um
TIME = "cnc_kernel_time_r"  # s
INCR = 10_000  # 0.1 um per mm
CONFIG = plc_machine({"10": "MOS", "11": "MVS_SVS", "12": "MVS_SNS", "13": "MNS_SNS"})
PROGRAM = "G01 X10 F6000\nN20 G01 X20 M{m}\nN30 G01 X30\nM30\n"


@dataclass
class Plc:
    service: ServiceProcess
    plc: pyads.Connection  # 851

    def read(self, name: str) -> Any:
        return self.plc.read_by_name(name)

    def x_mm(self) -> float:
        return self.read(X_POS) / INCR

    def until(self, predicate: Callable[[], bool]) -> None:
        deadline = time.monotonic() + WAIT_S
        while not predicate():
            assert time.monotonic() < deadline, "the PLC waited in vain"


@pytest.fixture(scope="module")
def plc(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Plc]:
    with pyads_service(tmp_path_factory.mktemp("plc-functions"), LOCAL_NET_ID, "--clock", "virtual",
                       config=CONFIG) as (service, (connection,)):
        yield Plc(service, connection)


def _start(client: Client, m: int) -> None:
    client.upload(f"m{m}.nc", PROGRAM.format(m=m).encode())
    client.run_program(f"m{m}.nc")


def _acknowledge_after(plc: Plc, k: int, stand_mm: float) -> None:
    """Let >= 0.1 s of kernel time pass with the path standing at ``stand_mm``, then
    acknowledge unit ``k``."""
    t0 = plc.read(TIME)
    plc.until(lambda: plc.read(TIME) >= t0 + 0.1)
    assert plc.x_mm() == stand_mm  # no motion while the PLC has not acknowledged
    assert plc.read(UNIT.format(k=k, field="state_r")) is True
    plc.plc.write_by_name(UNIT.format(k=k, field="command_w"), True)
    plc.until(lambda: plc.read(USED) == 0)
    assert plc.read(UNIT.format(k=k, field="command_w")) is True


@pytest.mark.parametrize(("m", "kind", "stand_mm"), [
    (11, 2, 10.0),  # MVS_SVS: output before N20's motion, which waits at X10
    (12, 4, 20.0),  # MVS_SNS: output before, the path waits at N20's end
    (13, 8, 20.0),  # MNS_SNS: output at N20's end, waited for there
])
def test_the_plc_acknowledges_and_the_path_waits_for_it(
    plc: Plc, m: int, kind: int, stand_mm: float
) -> None:
    with Client(plc.service.endpoint) as client:
        _start(client, m)
        plc.until(lambda: plc.read(USED) == 1)
        k = next(k for k in range(16) if plc.read(UNIT.format(k=k, field="state_r")))
        assert plc.read(UNIT.format(k=k, field="attribut_r.typ")) == 1  # M
        assert plc.read(UNIT.format(k=k, field="attribut_r.nr")) == m
        assert plc.read(UNIT.format(k=k, field="attribut_r.synch")) == kind
        if kind != 2:
            plc.until(lambda: plc.x_mm() == stand_mm)
        _acknowledge_after(plc, k, stand_mm)
        client.wait_program(timeout_s=WAIT_S)
        assert plc.x_mm() == 30.0


def test_mos_needs_no_acknowledge(plc: Plc) -> None:
    with Client(plc.service.endpoint) as client:
        _start(client, 10)
        client.wait_program(timeout_s=WAIT_S)
        assert plc.read(USED) == 0
        assert plc.x_mm() == 30.0


def test_an_acknowledge_without_a_pending_unit_is_refused(plc: Plc) -> None:
    with pytest.raises(pyads.ADSError) as refused:
        plc.plc.write_by_name(UNIT.format(k=15, field="command_w"), True)
    assert refused.value.err_code == 0x706  # ADS DEVICE_INVALIDDATA


def test_the_spindle_over_ads(plc: Plc) -> None:
    """S.. M3 waits for the speed (MVS_SVS); the PLC reads it and sets the override."""
    plc.plc.write_by_name("gpCh[0].spindle.override_w", 500, pyads.PLCTYPE_UINT)
    with Client(plc.service.endpoint) as client:
        client.upload("spindle.nc", b"S2000 M3\nG01 X1 F6000\nM30\n")
        client.run_program("spindle.nc")
        client.wait_program(timeout_s=WAIT_S)
    assert plc.read("gpCh[0].spindle.mode_r") == 2  # M03
    assert plc.read("gpCh[0].spindle.cmd_rev_r") == 1000 * 6000  # 0.001 deg/s: 1000 rpm
    assert plc.read("gpCh[0].spindle.active_rev_r") == 1000 * 6000
    assert plc.read("gpCh[0].spindle.speed_reached_r") is True
    with pytest.raises(pyads.ADSError) as refused:
        plc.plc.write_by_name("gpCh[0].spindle.override_w", 1501, pyads.PLCTYPE_UINT)
    assert refused.value.err_code == 0x706
    plc.plc.write_by_name("gpCh[0].spindle.override_w", 1000, pyads.PLCTYPE_UINT)
    plc.until(lambda: plc.read("gpCh[0].spindle.active_rev_r") == 2000 * 6000)
