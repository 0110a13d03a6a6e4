"""The alarm model (service/kernel/alarms.py) against NC programs with known errors, in
the real kernel on the virtual clock: every listed error and warning is an alarm with
its id, severity, class, channel, time stamps and place; acknowledge, RESET and the
bounds of the lists (docs/alarms.md)."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from cnc_objects.service.kernel.alarms import (
    AlarmClass,
    AlarmLog,
    AlarmState,
    Severity,
    class_of,
)
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.commands import (
    AcknowledgeAlarm,
    AcknowledgeAllAlarms,
    RefusalReason,
    ResetChannel,
    SetExecutionMode,
)
from cnc_objects.service.kernel.state import ErrorEntry
from tests.support.kernel import KernelHarness

SYNCHK, MACHINE_LOCK = 0x8, 0x40
EXAMPLE = (Path(__file__).resolve().parents[3] / "docs" / "examples"
           / "check-syntax.nc").read_text(encoding="utf-8")

#: NC programs with a known error: (text, id, line, column, class)
KNOWN_ERRORS = [
    pytest.param("G0 X1\nG1 X10\nM30\n", 20008, 2, 1, AlarmClass.DECODER, id="no-feed"),
    pytest.param("G0 X1\nG999 X2\nM30\n", 20120, 2, 1, AlarmClass.DECODER, id="unknown-g"),
    pytest.param("G0 X0 Y0\nG2 X10 Y0 R2 F100\nM30\n", 20144, 2, 1, AlarmClass.DECODER,
                 id="arc-radius-too-small"),
    pytest.param("G0 X1\nG1 X[1/0] F100\nM30\n", 20201, 2, 7, AlarmClass.DECODER,
                 id="division-by-zero"),
]


@pytest.fixture()
def harness():
    """A kernel of its own per test: alarms outlive programs."""
    with KernelHarness() as h:
        yield h


def _alarms(h: KernelHarness):
    return h.kernel.alarms.view


@pytest.mark.parametrize(("text", "error_id", "line", "column", "alarm_class"), KNOWN_ERRORS)
def test_a_program_error_raises_one_alarm_with_its_place(harness, text, error_id, line,
                                                          column, alarm_class) -> None:
    before_ns = time.time_ns()
    run = harness.run(text, "known.nc")
    assert run.channel.state == ChannelState.ERROR
    view = _alarms(harness)
    assert [a.id for a in view.active] == [error_id]
    alarm = view.active[0]
    assert (alarm.file, alarm.line) == ("known.nc", line)
    assert alarm.column == column
    assert alarm.alarm_class == alarm_class
    assert alarm.severity == Severity.ERROR and alarm.state == AlarmState.ACTIVE
    assert alarm.channel == 1 and alarm.sequence == view.raised == 1
    assert before_ns <= alarm.wall_ns <= time.time_ns()
    assert alarm.cycle > 0 and alarm.kernel_ns == alarm.cycle * harness.kernel.cycle_ns
    assert alarm.text == run.channel.errors.entries[0].text  # the same error as the channel lists
    assert view.history == view.active


def test_acknowledge_keeps_an_error_active_until_reset_clears_it(harness) -> None:
    harness.run("G1 X10\nM30\n")
    alarm = _alarms(harness).active[0]
    changes = _alarms(harness).changes
    assert harness.command(AcknowledgeAlarm(alarm.sequence)) is None
    view = _alarms(harness)
    assert [a.state for a in view.active] == [AlarmState.ACKNOWLEDGED]
    assert view.changes > changes
    assert harness.command(ResetChannel(0, True)) is None
    view = _alarms(harness)
    assert view.active == ()
    assert [(a.sequence, a.state) for a in view.history] == [(alarm.sequence,
                                                              AlarmState.CLEARED)]


def test_reset_clears_an_unacknowledged_error_too(harness) -> None:
    harness.run("G1 X10\nM30\n")
    assert harness.command(ResetChannel(0, True)) is None
    assert _alarms(harness).active == ()
    assert _alarms(harness).history[0].state == AlarmState.CLEARED


def test_a_warning_is_cleared_by_its_acknowledge(harness) -> None:
    assert harness.command(SetExecutionMode(0, SYNCHK)) is None
    run = harness.run("G1 X10 F100\nM30\n", "a.nc")
    assert run.channel.state == ChannelState.READY
    [warning] = _alarms(harness).active
    assert (warning.id, warning.severity) == (21309, Severity.WARNING)
    assert harness.command(AcknowledgeAlarm(warning.sequence)) is None
    assert _alarms(harness).active == ()
    assert _alarms(harness).history[0].state == AlarmState.CLEARED


def test_an_unknown_sequence_number_is_refused_with_a_sentence(harness) -> None:
    harness.run("G1 X10\nM30\n")
    refusal = harness.command(AcknowledgeAlarm(99))
    assert refusal is not None and refusal.reason == RefusalReason.NOT_FOUND
    assert "no alarm has the sequence number 99" in refusal.message
    assert "active alarms: 1" in refusal.message


def test_acknowledge_all_acknowledges_errors_and_clears_warnings(harness) -> None:
    assert harness.command(SetExecutionMode(0, SYNCHK)) is None
    harness.run("G1 X10 F100\nM30\n", "a.nc")  # warning 21309
    assert harness.command(SetExecutionMode(0, 0)) is None
    harness.run("G1 X10\nM30\n", "b.nc")  # error 20008
    assert [a.id for a in _alarms(harness).active] == [20008, 21309]  # newest first
    assert harness.command(AcknowledgeAllAlarms(True)) is None
    view = _alarms(harness)
    assert [(a.id, a.state) for a in view.active] == [(20008, AlarmState.ACKNOWLEDGED)]
    assert harness.command(AcknowledgeAllAlarms(False)) is None  # FALSE does nothing
    assert _alarms(harness).changes == view.changes


def test_the_findings_of_a_syntax_check_are_check_alarms(harness) -> None:
    assert harness.command(SetExecutionMode(0, SYNCHK | MACHINE_LOCK)) is None
    run = harness.run(EXAMPLE, "check_syntax.nc")
    assert run.channel.state == ChannelState.READY
    found = [(a.id, a.line, a.alarm_class, a.severity) for a in
             reversed(_alarms(harness).active) if a.id not in (21309, 21310)]
    assert found == [(i, line, AlarmClass.CHECK, Severity.WARNING) for i, line in
                     [(20113, 5), (20500, 8), (20310, 11), (20151, 14), (20121, 17)]]


def test_a_fault_checked_then_run_is_one_alarm_the_error(harness) -> None:
    """Issue 36: a syntax check, then a run of the same program, listed 21220 twice (as
    the check's warning and as the run's error)."""
    assert harness.command(SetExecutionMode(0, SYNCHK | MACHINE_LOCK)) is None
    harness.run("G1 X10 F100\nG1 Y10 Q7\nM30\n", "bad.nc")
    checked = [a for a in _alarms(harness).active if a.id == 21220]
    assert [a.severity for a in checked] == [Severity.WARNING]
    assert harness.command(SetExecutionMode(0, 0)) is None
    run = harness.run("G1 X10 F100\nG1 Y10 Q7\nM30\n", "bad.nc")
    assert run.channel.state == ChannelState.ERROR
    view = _alarms(harness)
    faults = [(a.id, a.severity, a.line) for a in view.active if a.id == 21220]
    assert faults == [(21220, Severity.ERROR, 2)]
    replaced = next(a for a in view.history if a.sequence == checked[0].sequence)
    assert replaced.state == AlarmState.CLEARED  # the warning stays in the history


def test_a_fault_raised_again_while_active_is_not_listed_twice() -> None:
    log = AlarmLog()
    first = log.raise_error(ErrorEntry(21309, "checked", warning=True), channel=1)
    assert log.raise_error(ErrorEntry(21309, "checked", warning=True), channel=1) is first
    log.raise_error(ErrorEntry(21309, "checked", warning=True), channel=2)  # another channel
    assert [(a.id, a.channel) for a in log.view.active] == [(21309, 2), (21309, 1)]


def test_a_kernel_reset_clears_every_alarm(harness) -> None:
    from cnc_objects.service.kernel.kernel import Control, ControlCommand

    harness.run("G1 X10\nM30\n")
    assert harness.command(ControlCommand(Control.RESET)) is None
    assert _alarms(harness).active == ()
    assert _alarms(harness).history[0].state == AlarmState.CLEARED


# ------------------------------------------------------------ the log alone


def _entry(n: int, warning: bool = False) -> ErrorEntry:
    return ErrorEntry(20000 + n, f"error {n}", warning=warning)


def test_the_history_keeps_the_last_n_newest_first() -> None:
    log = AlarmLog(history_max=3, active_max=10)
    for n in range(5):
        log.raise_error(_entry(n), channel=1)
    assert [a.sequence for a in log.view.history] == [5, 4, 3]
    assert [a.sequence for a in log.view.active] == [5, 4, 3, 2, 1]  # still active
    log.reset_channel(1)
    assert log.view.active == ()
    assert [a.state for a in log.view.history] == [AlarmState.CLEARED] * 3
    assert log.acknowledge(1) is not None  # left both lists: unknown now


def test_a_full_active_list_clears_its_oldest() -> None:
    log = AlarmLog(history_max=10, active_max=2)
    for n in range(3):
        log.raise_error(_entry(n), channel=1)
    assert [a.sequence for a in log.view.active] == [3, 2]
    assert log.view.history[-1].state == AlarmState.CLEARED


def test_reset_leaves_the_restart_alarms_and_other_channels() -> None:
    log = AlarmLog()
    log.raise_error(ErrorEntry(70901, "clone limits"), channel=1)  # axis configuration
    log.raise_error(_entry(1), channel=2)
    log.raise_error(_entry(2), channel=1)
    log.reset_channel(1)
    assert [(a.id, a.channel, a.severity) for a in log.view.active] == [
        (20001, 2, Severity.ERROR), (70901, 1, Severity.FATAL)]
    log.restart()
    assert log.view.active == ()


@pytest.mark.parametrize(("error_id", "expected"), [
    (20008, AlarmClass.DECODER), (50101, AlarmClass.PATH), (70910, AlarmClass.AXIS),
    (20533, AlarmClass.SERVICE), (20532, AlarmClass.SERVICE), (90001, AlarmClass.KERNEL),
    (50462, AlarmClass.AXIS),
])
def test_the_class_follows_the_id_ranges(error_id, expected) -> None:
    assert class_of(error_id) == expected
