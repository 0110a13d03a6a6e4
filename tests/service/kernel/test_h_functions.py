"""H functions (ISG's technology information to the PLC), cycle by cycle.

ISG: ``H<expr>``, the value rounded to an integer, a negative one an error, the same H
twice in a block error 20766; each H number has its synchronisation kind (P-CHAN-00027
``h_synch[i]``) and time (P-CHAN-00026 ``h_prozess_zeit[i]``), and reaches the PLC as a
technology unit of type H (HLI_M_H_PROZESS ``.nr``), as M functions do.
"""

from __future__ import annotations

from typing import Any

import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.commands_technology import AcknowledgeTechnoUnit
from cnc_objects.service.kernel.nc.errors import NcErrorId
from cnc_objects.service.kernel.plc_functions import TechnoType
from cnc_objects.service.kernel.state import Snapshot
from cnc_objects.service.machine_config import DEFAULT_MACHINE, SyncKind
from tests.support.kernel import KernelHarness
from tests.support.plc_recorder import Recorder

H_KINDS = {"20": "MOS", "21": "MVS_SVS", "23": "MNS_SNS", "24": "NO_SYNCH"}


def _config(auto: bool = False, h_times_us: dict[str, int] | None = None) -> Any:
    channels = [dict(c) for c in DEFAULT_MACHINE["channels"]]
    channels[0]["techno"] = {"h_synch": H_KINDS, "auto_acknowledge": auto,
                             "h_prozess_zeit": h_times_us or {}}
    return build_config({"channels": channels})


def _x(s: Snapshot) -> float:
    return s.channels[0].axes[0].position_mm


def _units(s: Snapshot) -> Any:
    return s.channels[0].plc_functions.units


PROGRAM = "G01 X10 F6000\nN20 G01 X20 H{h}\nN30 G01 X30\nM30\n"


def test_an_mvs_svs_h_function_is_output_before_the_motion_which_waits_for_the_plc() -> None:
    with KernelHarness(config=_config()) as h:
        rec = Recorder(h)
        h.start(PROGRAM.format(h=21))
        out = h.wait_for(lambda s: bool(_units(s)))
        unit = _units(out)[0]
        assert (unit.type, unit.number, unit.sync, unit.acknowledged) == (
            TechnoType.H, 21, SyncKind.MVS_SVS, False)
        assert _x(out) == 10.0
        h.wait_for(lambda s: s.cycle >= out.cycle + 30)
        assert h.command(AcknowledgeTechnoUnit(0, 0)) is None
        h.wait_for(lambda s: not s.channels[0].plc_functions.used_units)
        acked = rec.first(lambda s: _units(s) and not s.channels[0].plc_functions.used_units)
        assert all(_x(s) == 10.0 for s in rec.rows if out.cycle <= s.cycle < acked.cycle)
        assert rec.first(lambda s: _x(s) > 10.0).cycle == acked.cycle
        assert h.wait().channel.state == ChannelState.READY


def test_an_mns_sns_h_function_is_output_at_the_block_end() -> None:
    with KernelHarness(config=_config(auto=True)) as h:
        rec = Recorder(h)
        assert h.run(PROGRAM.format(h=23)).channel.state == ChannelState.READY
        out = rec.first(lambda s: bool(_units(s)))
        assert _x(out) == 20.0 and _units(out)[0].type == TechnoType.H


def test_a_mos_h_function_never_stops_the_path_and_no_synch_is_not_output() -> None:
    with KernelHarness(config=_config()) as h:
        rec = Recorder(h)
        assert h.run(PROGRAM.format(h=20)).channel.state == ChannelState.READY
        unit = _units(rec.rows[-1])[0]
        assert (unit.type, unit.number, unit.acknowledged) == (TechnoType.H, 20, True)
        assert not [s for s in rec.rows if 10.0 < _x(s) < 30.0
                    and s.channels[0].path.path_velocity_mm_s == 0.0]
    with KernelHarness(config=_config()) as h:
        h.run(PROGRAM.format(h=24))
        assert _units(h.kernel.snapshot) == ()


def test_the_embedded_plc_acknowledges_an_h_function_after_its_time() -> None:
    with KernelHarness(config=_config(auto=True, h_times_us={"21": 15_000})) as h:
        rec = Recorder(h)
        assert h.run(PROGRAM.format(h=21)).channel.state == ChannelState.READY
        out = rec.first(lambda s: bool(_units(s)))
        acked = rec.first(lambda s: _units(s) and not s.channels[0].plc_functions.used_units)
        assert acked.cycle - out.cycle == round(0.015 / (h.config.cycle_ms / 1000.0))


def test_m_and_h_functions_of_one_block_are_output_together() -> None:
    with KernelHarness(config=_config(auto=True)) as h:
        rec = Recorder(h)
        assert h.run("G01 X10 F6000\nG01 X20 M8 H21 H20\nM30\n").channel.state \
            == ChannelState.READY
        listed = {(u.type, u.number) for u in _units(rec.rows[-1])}
        assert {(TechnoType.M, 8), (TechnoType.H, 21), (TechnoType.H, 20)} <= listed


def test_an_h_value_is_rounded_as_isg_does() -> None:
    with KernelHarness(config=_config(auto=True)) as h:
        rec = Recorder(h)
        assert h.run("G01 X10 F6000 H[41.2 / 2]\nM30\n").channel.state == ChannelState.READY
        assert [u.number for u in _units(rec.rows[-1])] == [21]


@pytest.mark.parametrize(("line", "error_id", "column"), [
    ("G01 X10 F6000 H5 H5", NcErrorId.H_FUNCTION_TWICE, 18),
    ("G01 X10 F6000 H-1", NcErrorId.INVALID_H_CODE, 15),
])
def test_a_bad_h_word_is_an_isg_error_with_line_and_column(
    line: str, error_id: NcErrorId, column: int
) -> None:
    with KernelHarness(config=_config(auto=True)) as h:
        run = h.run(f"G01 X1 F600\n{line}\nM30\n")
        assert run.channel.state == ChannelState.ERROR
        error = run.channel.errors.entries[0]
        assert (error.id, error.line, error.column) == (int(error_id), 2, column)
