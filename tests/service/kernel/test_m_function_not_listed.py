"""M functions not in the channel's list (issue 39).

ISG: P-CHAN-00041 ``m_synch[i]`` defaults to NOT_VALID
(infosys.beckhoff.com/content/1033/tf5200_channel_parameter/148909195.html), and "M
functions not defined are indicated as unknown M functions by an error message after NC
program start and decoding is aborted" (tf5200_hli_interface/174821387.html). The id is
20160 "Unknown internal M-function" (tf5200_diagnosis/250945931.html: "Ensure that the M
function is defined in the channel parameters P-CHAN-00041"); ISG's page gives it for an
M above the list's range, no page gives another id for an unlisted M inside it.
"""

from __future__ import annotations

from typing import Any

from cnc_objects.protocol.values import ExecutionMode
from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.commands import SetExecutionMode
from cnc_objects.service.machine_config import DEFAULT_MACHINE, SyncKind
from tests.support.kernel import KernelHarness

PROGRAM = "G01 X10 F6000\nN20 G01 X20 M55\nM30\n"  # M55: listed nowhere


def _config(techno: dict[str, Any]) -> Any:
    channels = [dict(c) for c in DEFAULT_MACHINE["channels"]]
    channels[0]["techno"] = techno
    return build_config({"channels": channels})


def test_an_m_function_the_list_lacks_is_isg_error_20160_at_its_word() -> None:
    with KernelHarness() as h:
        run = h.run(PROGRAM)
        assert run.channel.state == ChannelState.ERROR
        error = run.channel.errors.entries[0]
        assert (error.id, error.line, error.column) == (20160, 2, 13)
        assert "M55" in error.text and error.file == "test.nc"
        assert run.channel.axes[0].position_mm == 10.0  # N20 never moved


def test_the_syntax_check_reports_it_too() -> None:
    with KernelHarness() as h:
        check = int(ExecutionMode.SYNCHK | ExecutionMode.MACHINE_LOCK)
        assert h.command(SetExecutionMode(0, check)) is None
        run = h.run(PROGRAM)
        assert [(e.id, e.line) for e in run.channel.errors.entries if e.id != 21309] == [
            (20160, 2)]


def test_the_default_machine_lists_the_m_functions_its_programs_use() -> None:
    with KernelHarness() as h:
        for m in (6, 7, 8, 9, 10, 11, 12, 13, 25, 40, 80):
            assert h.config.channels[0].techno.kind(1, m) == SyncKind.MVS_SVS, m
        run = h.run("G01 X10 F6000\nM7 M8\nM25\nM9\nM30\n")
        assert run.channel.state == ChannelState.READY


def test_a_configured_default_kind_still_takes_unlisted_m_functions() -> None:
    with KernelHarness(config=_config({"m_synch_default": "MOS"})) as h:
        assert h.config.channels[0].techno.kind(1, 55) == SyncKind.MOS
        run = h.run(PROGRAM)
        assert run.channel.state == ChannelState.READY
        assert [u.number for u in run.final.channels[0].plc_functions.units] == [55]
