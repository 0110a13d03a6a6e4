"""ISG's manual mode inside a program (G200, G201, G202) in the real kernel, cycle by cycle.

G200 stops the program at its block; the named axes jog (their motion is a manual offset
added to the path's output) until START, then the program goes on from there with the
offset kept. G201 lets the named axes jog while the path runs, until G202. Jogs of axes
G200/G201 did not name, or outside a running program, are refused; software limits hold
for path plus offset.
"""

from __future__ import annotations

from typing import Any

import pytest

from cnc_objects.protocol.values import ChannelState, ManualOperationMode
from cnc_objects.protocol.wait_reasons import WaitReason
from cnc_objects.service.kernel.commands import Feedhold, RefusalReason, StartProgram
from cnc_objects.service.kernel.commands_manual import ManualAxisCommand
from cnc_objects.service.kernel.manual_view import DisplayState
from cnc_objects.service.kernel.nc.errors import NcErrorId
from cnc_objects.service.kernel.state import Snapshot
from tests.support.kernel import KernelHarness
from tests.support.manual_machine import LIMIT_MAX_MM, machine
from tests.support.plc_recorder import Recorder

INCREMENT_01UM = 20_000  # 2 mm


@pytest.fixture
def k() -> Any:
    with KernelHarness(config=machine()) as harness:
        yield harness


def write(k: KernelHarness, action: str, value: int | bool, axis: int = 0) -> Any:
    return k.command(ManualAxisCommand(0, axis, action, value))


def _x(s: Snapshot) -> float:
    return s.channels[0].axes[0].position_mm


def _y(s: Snapshot) -> float:
    return s.channels[0].axes[1].position_mm


def _view(s: Snapshot, axis: int = 0) -> Any:
    return s.channels[0].manual[axis]


def _incremental(k: KernelHarness, axis: int = 0) -> None:
    assert write(k, "operation_mode", ManualOperationMode.INCREMENTAL, axis) is None
    assert write(k, "increment", INCREMENT_01UM, axis) is None


def test_g200_stops_the_program_jogs_the_axis_and_start_goes_on_with_the_offset(k: Any) -> None:
    k.start("G01 X1 Y0 F600\nG200 X1\nG01 X4 Y1\nM30\n")
    stopped = k.wait_for(lambda s: s.channels[0].program.waiting_for_start)
    assert (_x(stopped), _view(stopped).state) == (1.0, DisplayState.ENABLED)
    assert stopped.channels[0].wait_reason == WaitReason.MANUAL_MODE
    assert _view(stopped, 1).state == DisplayState.DEACTIVATED  # Y was not named
    _incremental(k)
    assert write(k, "jog_plus", True) is None
    jogged = k.wait_for(lambda s: _x(s) == 3.0 and not _view(s).moving)
    assert _view(jogged).offset_01um == INCREMENT_01UM
    assert jogged.channels[0].state == ChannelState.ACTIVE  # the program still runs
    _incremental(k, axis=1)
    refused = write(k, "jog_plus", True, axis=1)
    assert refused is not None and "G200/G201" in refused.message
    assert k.command(StartProgram(0, True)) is None  # "continue motion"
    run = k.wait()
    assert run.channel.state == ChannelState.READY
    assert (_x(run.final), _y(run.final)) == (6.0, 1.0)  # X4 + 2 mm offset, Y as programmed
    assert _view(run.final).state == DisplayState.DEACTIVATED
    assert _view(run.final).offset_01um == 0  # the offset ends with the program


def test_start_is_refused_while_a_g200_jog_still_moves(k: Any) -> None:
    k.start("G200 X1\nM30\n")
    k.wait_for(lambda s: s.channels[0].program.waiting_for_start)
    assert write(k, "operation_mode", ManualOperationMode.CONTINUOUS) is None
    assert write(k, "jog_plus", True) is None
    k.wait_for(lambda s: _view(s).moving)
    refused = k.command(StartProgram(0, True))
    assert refused is not None and refused.reason == RefusalReason.NOT_READY
    assert "still moves" in refused.message
    assert write(k, "jog_plus", False) is None
    k.wait_for(lambda s: not _view(s).moving)
    assert k.command(StartProgram(0, True)) is None
    assert k.wait().channel.state == ChannelState.READY


def test_a_g200_jog_stops_at_the_software_limit_of_path_plus_offset(k: Any) -> None:
    k.start("G01 X7 F6000\nG200\nM30\n")
    k.wait_for(lambda s: s.channels[0].program.waiting_for_start)
    _incremental(k)  # 2 mm from X7 would pass the limit at 8 mm
    assert write(k, "jog_plus", True) is None
    s = k.wait_for(lambda s: _view(s).limit_warning and not _view(s).moving)
    assert _x(s) == LIMIT_MAX_MM
    assert _view(s).offset_01um == 10_000


def test_g201_jogs_in_parallel_to_the_path_until_g202(k: Any) -> None:
    rec = Recorder(k)
    k.start("G201 Y1\nG01 X5 F60\nG202\nG01 X6\nM30\n")
    moving = k.wait_for(lambda s: 0.5 < _x(s) < 4.0 and _view(s, 1).state != 0)
    assert _view(moving, 1).state == DisplayState.ENABLED
    _incremental(k, axis=1)
    assert write(k, "jog_plus", True, axis=1) is None
    done = k.wait_for(lambda s: _y(s) == 2.0 and not _view(s, 1).moving)
    assert _x(done) < 5.0  # Y moved while the path ran on in X
    run = k.wait()
    assert run.channel.state == ChannelState.READY
    assert (_x(run.final), _y(run.final)) == (6.0, 2.0)  # the offset stayed after G202
    after_g202 = [s for s in rec.rows if _x(s) > 5.0]
    assert after_g202 and all(_view(s, 1).state == DisplayState.DEACTIVATED
                              for s in after_g202)
    assert all(s.channels[0].path.path_velocity_mm_s > 0.0 for s in rec.rows
               if 0.1 < _x(s) < 4.9)  # the path never stopped for the jog


def test_a_feedhold_brakes_the_g201_jog_too(k: Any) -> None:
    k.start("G201 Y1\nG01 X5 F60\nM30\n")
    k.wait_for(lambda s: _x(s) > 0.5)
    assert write(k, "operation_mode", ManualOperationMode.CONTINUOUS, axis=1) is None
    assert write(k, "jog_plus", True, axis=1) is None
    k.wait_for(lambda s: _view(s, 1).moving)
    assert k.command(Feedhold(0, True)) is None
    held = k.wait_for(lambda s: not _view(s, 1).moving
                      and s.channels[0].path.path_velocity_mm_s == 0.0)
    assert held.channels[0].state == ChannelState.HOLD
    refused = write(k, "jog_plus", True, axis=1)
    assert refused is not None and "ACTIVE" in refused.message


def test_jogging_an_axis_without_g200_in_a_running_program_is_refused(k: Any) -> None:
    k.start("G01 X5 F60\nM30\n")
    k.wait_for(lambda s: _x(s) > 0.1)
    _incremental(k)
    refused = write(k, "jog_plus", True)
    assert refused is not None and refused.reason == RefusalReason.NOT_READY
    assert "MANUAL" in refused.message and "G200/G201" in refused.message


@pytest.mark.parametrize(("line", "error_id", "column"), [
    ("G200 G201 X1", NcErrorId.MANUAL_MODE_TWICE, 6),
    ("G201", NcErrorId.MANUAL_MODE_WITHOUT_AXES, 1),
    ("G200 Q1", NcErrorId.UNKNOWN_WORD, 6),
])
def test_bad_manual_mode_blocks_are_isg_errors_with_line_and_column(
    k: Any, line: str, error_id: NcErrorId, column: int
) -> None:
    run = k.run(f"G01 X1 F600\n{line}\nM30\n")
    assert run.channel.state == ChannelState.ERROR
    error = run.channel.errors.entries[0]
    assert (error.id, error.line, error.column) == (int(error_id), 2, column)
