"""The channel's transition table is what the real kernel does.

Every entry of ``channel_transitions.TRANSITIONS`` is reached through the real kernel
(commands as the service submits them, programs on the virtual clock) and must produce
its target; every pair outside the table is refused (client events: a NOT_READY
``Refusal``, the channel unchanged) or raises ``TransitionNotAllowed`` (internal events,
which no client input can cause).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from cnc_objects.protocol.values import ExecutionMode
from cnc_objects.service.kernel.channel_mode import IDLE_STATES, ChannelMode, ChannelState
from cnc_objects.service.kernel.channel_transitions import (
    TRANSITIONS,
    ChannelEvent,
    Target,
    TransitionNotAllowed,
    allowed,
    next_state,
    render_table,
    resolve,
)
from cnc_objects.service.kernel.commands import (
    Feedhold,
    ManualBlock,
    Refusal,
    RefusalReason,
    ResetChannel,
    SelectMode,
    SelectProgram,
    SetExecutionMode,
    SetFeedOverride,
    SetSingleBlock,
    StartProgram,
)
from cnc_objects.service.kernel.kernel_state import KernelState
from cnc_objects.service.kernel.state import DecoderFlag, ErrorEntry
from tests.support.kernel import KernelHarness

S, E = ChannelState, ChannelEvent
LONG = "long.nc"  # G91: runs for about 6000 s of kernel time, wherever the axes stand
PROGRAMS = {
    LONG: "G91 G1 X100 F1\nM30\n",
    "short.nc": "G91 G1 X1 F6000\nM30\n",
    "limit.nc": "G91 G1 X1 F6000\nG90 G1 X5000\nM30\n",  # X5000: beyond the soft limit
    "brake.nc": "G91 G1 X5 F6000\nM30\n",  # brakes over 1 mm (20 cycles) at its end
    "check.nc": "G91 G1 X1 F6000\nG1 X2\nG1 X3\nM30\n",
}
_INTERNAL = {E.CHECK_PAUSE, E.PROGRAM_END, E.FAIL}


@pytest.fixture(scope="module")
def harness():
    with KernelHarness(dict(PROGRAMS)) as h:
        yield h


# ---------------------------------------------------------------- commands of the test


class Report:
    """A start-up message that is an error (``ChannelRunner.report``): FAIL in any state."""

    def apply(self, state: KernelState) -> Refusal | None:
        state.runners[0].report(ErrorEntry(1, "a test error stops the channel"))
        return None


@dataclass(frozen=True)
class TryInternal:
    """The runner moves by an internal event, on the cycle thread; what it raised."""

    event: ChannelEvent
    raised: list[Exception] = field(default_factory=list)

    def apply(self, state: KernelState) -> Refusal | None:
        try:
            state.runners[0]._move(self.event)
        except TransitionNotAllowed as exc:
            self.raised.append(exc)
        return None


# ---------------------------------------------------------------- reaching a state


def _ch(h: KernelHarness) -> Any:
    return h.kernel.snapshot.channels[0]


def _ok(h: KernelHarness, command: Any) -> None:
    refusal = h.command(command)
    assert refusal is None, refusal


def _reach(h: KernelHarness, state: ChannelState, *, mdi: bool = False) -> None:
    """Bring channel 1 to ``state`` from wherever it is (READY: AUTOMATIC with a
    program, or ``mdi``: MDI after a manual block; SELECTED: MDI)."""
    _ok(h, ResetChannel(0, True))
    _ok(h, SetSingleBlock(0, False))
    _ok(h, SetExecutionMode(0, 0))
    _ok(h, SelectMode(0, ChannelMode.STANDBY))
    if state == S.SELECTED:
        _ok(h, SelectMode(0, ChannelMode.MDI))
    elif state == S.READY and mdi:
        h.mdi("G91 G1 X0.1 F6000")
    elif state == S.READY:
        _ok(h, SelectProgram(0, LONG))
    elif state in (S.ACTIVE, S.HOLD):
        _ok(h, SelectProgram(0, LONG))
        _ok(h, StartProgram(0, True))
        if state == S.HOLD:
            _ok(h, Feedhold(0, True))
    elif state == S.ERROR:
        h.home()  # the software limits count once the axes are referenced
        _ok(h, SelectProgram(0, "limit.nc"))
        h.begin(StartProgram(0, True))
        h.wait()
    assert _ch(h).state == state


def _key(ch: Any) -> tuple:
    return ch.mode, ch.state, ch.program.program_name, ch.errors.count, ch.program.waiting_for_start


def _expected(state: ChannelState, event: ChannelEvent, ch: Any) -> ChannelState:
    """The table's target for ``ch`` (named targets resolved with its mode and program)."""
    return resolve(TRANSITIONS[state][event], ch.mode, bool(ch.program.program_name))


# ---------------------------------------------------------------- the entries


def _select_mode(h: KernelHarness) -> None:
    _ok(h, SelectMode(0, ChannelMode.AUTOMATIC))


def _select_program(h: KernelHarness) -> None:
    _ok(h, SelectProgram(0, LONG))


def _manual_block(h: KernelHarness) -> None:
    _ok(h, ManualBlock(0, "G91 G1 X100 F1"))


def _start(h: KernelHarness) -> None:
    _ok(h, StartProgram(0, True))


def _hold(h: KernelHarness) -> None:
    _ok(h, Feedhold(0, True))


def _reset(h: KernelHarness) -> None:
    _ok(h, ResetChannel(0, True))


def _report(h: KernelHarness) -> None:
    before = _ch(h).errors.count
    _ok(h, Report())
    assert _ch(h).errors.count == before + 1


def _to_the_end(h: KernelHarness) -> None:
    _ok(h, ResetChannel(0, True))
    _ok(h, SelectProgram(0, "short.nc"))
    h.begin(StartProgram(0, True))
    assert h.wait().channel.errors.count == 0


def _program_error(h: KernelHarness) -> None:
    _ok(h, ResetChannel(0, True))
    h.home()  # the software limits count once the axes are referenced
    _ok(h, SelectProgram(0, "limit.nc"))
    h.begin(StartProgram(0, True))
    assert h.wait().channel.errors.entries[0].line == 2


def _check_pauses(h: KernelHarness) -> None:
    """A syntax check with single step waits after its first line."""
    _ok(h, ResetChannel(0, True))
    _ok(h, SetExecutionMode(0, ExecutionMode.SYNCHK | ExecutionMode.MACHINE_LOCK))
    _ok(h, SetSingleBlock(0, True))
    _ok(h, SelectProgram(0, "check.nc"))
    _ok(h, StartProgram(0, True))
    ch = _ch(h)
    assert ch.program.waiting_for_start and ch.program.decoder_flags & DecoderFlag.WAIT_CONTINUE


def _check_still_paused(h: KernelHarness) -> None:
    """The paused check, in HOLD, pauses again in every cycle (a command makes one)."""
    _check_pauses(h)
    cycle = h.kernel.snapshot.cycle
    _ok(h, SetFeedOverride(0, 1000))
    assert h.kernel.snapshot.cycle > cycle
    assert _ch(h).program.waiting_for_start


def _end_while_braking(h: KernelHarness) -> None:
    """Feedhold on the braking curve before M30: the path still ends there, in HOLD."""
    _ok(h, ResetChannel(0, True))
    _ok(h, SelectProgram(0, "brake.nc"))
    states: list[int] = []
    sent_at: list[int] = []  # index in ``states`` when the feedhold was submitted
    last_v = [0.0]

    def watch(snap: Any) -> bool:
        ch = snap.channels[0]
        if sent_at and states[-1] != S.HOLD and states[-1] != S.ACTIVE:
            return True  # ended: record no more
        states.append(ch.state)
        if not sent_at and ch.state == S.ACTIVE and 0.0 < ch.path.path_velocity_mm_s < last_v[0]:
            sent_at.append(len(states))
            h.kernel.submit(Feedhold(0, True), lambda refusal: None)
        last_v[0] = ch.path.path_velocity_mm_s
        return bool(sent_at) and ch.state not in (S.ACTIVE, S.HOLD)

    ended = h.watch(watch)
    h.begin(StartProgram(0, True))
    assert ended.wait(30.0), "the program did not end"
    after = states[sent_at[0]:]
    assert after[0] == S.HOLD, after  # applied in the next cycle, still braking
    assert set(after[:-1]) == {S.HOLD} and after[-1] == S.READY, after
    assert _ch(h).errors.count == 0


@dataclass(frozen=True)
class Scenario:
    """How an entry of the table is reached: the state before (``mdi``: MDI/READY) and
    what makes the event happen."""

    act: Callable[[KernelHarness], None]
    mdi: bool = False


SCENARIOS: dict[tuple[ChannelState, ChannelEvent], Scenario] = {
    (S.DESELECTED, E.SELECT_MODE): Scenario(_select_mode),
    (S.DESELECTED, E.SELECT_PROGRAM): Scenario(_select_program),
    (S.DESELECTED, E.START): Scenario(_manual_block),
    (S.DESELECTED, E.FAIL): Scenario(_report),
    (S.DESELECTED, E.RESET): Scenario(_reset),
    (S.SELECTED, E.SELECT_MODE): Scenario(_select_mode),
    (S.SELECTED, E.SELECT_PROGRAM): Scenario(_select_program),
    (S.SELECTED, E.START): Scenario(_manual_block),
    (S.SELECTED, E.FAIL): Scenario(_report),
    (S.SELECTED, E.RESET): Scenario(_reset),
    (S.READY, E.SELECT_MODE): Scenario(_select_mode),
    (S.READY, E.SELECT_PROGRAM): Scenario(_select_program),
    (S.READY, E.START): Scenario(_start),
    (S.READY, E.FAIL): Scenario(_report),
    (S.READY, E.RESET): Scenario(_reset),
    (S.ACTIVE, E.HOLD): Scenario(_hold),
    (S.ACTIVE, E.CHECK_PAUSE): Scenario(_check_pauses),
    (S.ACTIVE, E.PROGRAM_END): Scenario(_to_the_end),
    (S.ACTIVE, E.FAIL): Scenario(_program_error),
    (S.ACTIVE, E.RESET): Scenario(_reset),
    (S.HOLD, E.RESUME): Scenario(_start),
    (S.HOLD, E.CHECK_PAUSE): Scenario(_check_still_paused),
    (S.HOLD, E.PROGRAM_END): Scenario(_end_while_braking),
    (S.HOLD, E.FAIL): Scenario(_report),
    (S.HOLD, E.RESET): Scenario(_reset),
    (S.ERROR, E.FAIL): Scenario(_report),
    (S.ERROR, E.RESET): Scenario(_reset),
}
# Scenarios whose action starts the run itself (from READY): the state before is READY.
_STARTS_ITSELF = {(S.ACTIVE, E.CHECK_PAUSE), (S.ACTIVE, E.PROGRAM_END), (S.ACTIVE, E.FAIL),
                  (S.HOLD, E.CHECK_PAUSE), (S.HOLD, E.PROGRAM_END)}
ENTRIES = [(s, e) for s, row in TRANSITIONS.items() for e in row]
MISSING = [(s, e) for s in S for e in E if e not in TRANSITIONS.get(s, {})]


def test_every_entry_of_the_table_has_a_scenario() -> None:
    assert set(SCENARIOS) == set(ENTRIES)


@pytest.mark.parametrize(("state", "event"), ENTRIES, ids=lambda v: v.name)
def test_an_entry_of_the_table_produces_its_target(harness, state, event) -> None:
    scenario = SCENARIOS[(state, event)]
    _reach(harness, S.READY if (state, event) in _STARTS_ITSELF else state, mdi=scenario.mdi)
    scenario.act(harness)
    ch = _ch(harness)
    assert ch.state == _expected(state, event, ch)


# ---------------------------------------------------------------- the named targets


@pytest.mark.parametrize(("mode", "target"), [
    (ChannelMode.STANDBY, S.DESELECTED), (ChannelMode.AUTOMATIC, S.SELECTED),
    (ChannelMode.MDI, S.SELECTED), (ChannelMode.MANUAL, S.SELECTED),
])
def test_selecting_a_mode_goes_to_deselected_in_standby_else_selected(mode, target) -> None:
    with KernelHarness(dict(PROGRAMS)) as h:
        _ok(h, SelectProgram(0, LONG))  # a selected program does not make it READY
        _ok(h, SelectMode(0, mode))
        assert _ch(h).state == target == resolve(Target.MODE_SELECTED, mode, True)


@pytest.mark.parametrize(("mode", "program", "target"), [
    (ChannelMode.STANDBY, False, S.DESELECTED), (ChannelMode.AUTOMATIC, True, S.READY),
    (ChannelMode.AUTOMATIC, False, S.SELECTED), (ChannelMode.MDI, False, S.SELECTED),
    (ChannelMode.MANUAL, False, S.SELECTED),
])
def test_reset_goes_to_ready_with_a_program_in_automatic(mode, program, target) -> None:
    with KernelHarness(dict(PROGRAMS)) as h:
        if program:
            _ok(h, SelectProgram(0, LONG))
        _ok(h, SelectMode(0, mode))
        _ok(h, Report())  # from ERROR
        _ok(h, ResetChannel(0, True))
        ch = _ch(h)
        assert (ch.mode, ch.state) == (mode, target)
        assert target == resolve(Target.AFTER_RESET, mode, program)


# ---------------------------------------------------------------- outside the table

_COMMAND_OF = {
    E.SELECT_MODE: SelectMode(0, ChannelMode.AUTOMATIC),
    E.SELECT_PROGRAM: SelectProgram(0, LONG),
    E.START: ManualBlock(0, "G91 G1 X1 F6000"),
    E.RESUME: StartProgram(0, True),
    E.HOLD: Feedhold(0, True),
}


@pytest.mark.parametrize(("state", "event"), [p for p in MISSING if p[1] not in _INTERNAL],
                         ids=lambda v: v.name)
def test_a_command_outside_the_table_is_refused_and_changes_nothing(
        harness, state, event) -> None:
    # in AUTOMATIC/READY START is the program start: READY is MDI/READY here
    _reach(harness, state, mdi=state == S.READY)
    before = _key(_ch(harness))
    refusal = harness.command(_COMMAND_OF[event])
    assert refusal is not None and refusal.reason == RefusalReason.NOT_READY, refusal
    assert "channel 1 is" in refusal.message
    assert _key(_ch(harness)) == before


@pytest.mark.parametrize(("state", "event"), [p for p in MISSING if p[1] in _INTERNAL],
                         ids=lambda v: v.name)
def test_an_internal_event_outside_the_table_raises(harness, state, event) -> None:
    _reach(harness, state)
    before = _key(_ch(harness))
    attempt = TryInternal(event)
    _ok(harness, attempt)
    assert len(attempt.raised) == 1
    assert event.name in str(attempt.raised[0]) and state.name in str(attempt.raised[0])
    assert _key(_ch(harness)) == before
    with pytest.raises(TransitionNotAllowed):
        next_state(state, event, ChannelMode.AUTOMATIC, True)


def test_the_idle_states_are_those_that_may_choose_a_mode_or_start() -> None:
    for event in (E.SELECT_MODE, E.SELECT_PROGRAM, E.START):
        assert {s for s in S if allowed(s, event)} == IDLE_STATES


def test_docs_show_the_table_as_it_is() -> None:
    kernel_md = (Path(__file__).parents[3] / "docs" / "kernel.md").read_text()
    assert render_table() in kernel_md


def test_reset_and_fail_are_allowed_in_every_state() -> None:
    assert all(allowed(s, E.RESET) and allowed(s, E.FAIL) for s in S)
