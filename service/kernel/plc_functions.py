"""M, S and T functions on their way to the PLC, with ISG's synchronisation kinds.

A decoded block's technology words (M other than program flow, H, S, T) are output to
the PLC side as technology units (ISG ``gpCh[ch]^.techno_unit_std_sync[i]``); the kind
of each function (P-CHAN-00041 ``m_synch[i]``, P-CHAN-00027 ``h_synch[i]``, P-CHAN-00081
``s_synch``, the spindle's ``m3_synch`` ..) says when it is output and when the path waits
for its acknowledge:

* MOS: output when the block's motion starts, never waited for;
* MVS_SVS: output before the motion, which starts only after the acknowledge;
* MVS_SNS: output before the motion; the block end is planned as a stop only while the
  acknowledge is outstanding (``stops_to_release``), a late one stops the path there;
* MNS_SNS: output at the block end, the path waits there for the acknowledge.

``split`` turns a motion block with technology into up to three blocks the path runs in
order: a pre block without motion (its end is the motion's start; ``StopKind.TECHNOLOGY``
when a function waits there), the motion, and a post block at its end. The path stands
at a TECHNOLOGY stop until ``all_acknowledged``. Spindle functions (M3, M4, M5, M19, S)
are acknowledged by the spindle (speed reached, stopped, oriented), the others by the
PLC, or by the embedded PLC after the function's time (P-CHAN-00040 ``m_prozess_zeit``)
while ``auto_acknowledge`` is on.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from enum import IntEnum
from typing import Protocol

from cnc_objects.protocol.values import CoolantState

from ..machine_config import PlcConfig, PlcFunctionsConfig, SyncKind
from .nc.blocks import Block, StopKind
from .spindle import SPINDLE_M_FUNCTIONS, Spindle


class TechnoType(IntEnum):
    """What a technology unit carries (HLI_M_H_PROZESS / HLI_T_PROZESS / S data)."""

    M = 1  # M function: ``number`` is the M number
    H = 2  # H function: ``number`` is the H number
    S = 3  # spindle speed: ``number`` is S in rpm
    T = 4  # tool: ``number`` is the T number


# where a kind is output: before the motion (at the pre block) or after it
_OUTPUT_BEFORE = frozenset({SyncKind.MOS, SyncKind.MVS_SVS, SyncKind.MVS_SNS})
_WAIT_BEFORE = frozenset({SyncKind.MVS_SVS})
_WAIT_AFTER = frozenset({SyncKind.MVS_SNS, SyncKind.MNS_SNS})
_NO_WAIT = frozenset({SyncKind.NO_SYNCH, SyncKind.MOS})


@dataclass(frozen=True, slots=True)
class TechnoUnit:
    """One output technology function (``techno_unit_std_sync[i]``)."""

    type: TechnoType
    number: int  # M / T number, S in rpm
    sync: SyncKind
    output_s: float  # channel time it was output
    acknowledged: bool  # the PLC (or the embedded PLC) acknowledged it
    ack_due_s: float | None  # when the embedded PLC acknowledges (None: the PLC must)

    @property
    def pending(self) -> bool:
        """Output and waiting for its acknowledge."""
        return not self.acknowledged


@dataclass(frozen=True, slots=True)
class PlcFunctionsUnit:
    """What the PLC side reads: the output units, in order; replaced on every change."""

    units: tuple[TechnoUnit, ...] = ()  # techno_unit_std_sync[0..]
    output_count: int = 0  # functions output since the channel started
    coolant: CoolantState = CoolantState.OFF  # M7/M8 output, M9 or RESET: OFF

    @property
    def used_units(self) -> int:
        """``used_units_std_sync_r``: units waiting for the PLC's acknowledge."""
        return sum(1 for u in self.units if u.pending)


# M7 mist on, M8 flood on, M9 both off: the coolant state after each (project: ISG
# leaves coolant to the PLC; the state follows the output, RESET switches it off)
_COOLANT: dict[int, Callable[[CoolantState], CoolantState]] = {
    7: lambda c: CoolantState(c | CoolantState.MIST),
    8: lambda c: CoolantState(c | CoolantState.FLOOD),
    9: lambda c: CoolantState.OFF,
}

UNITS_KEPT = 16  # acknowledged units stay readable until this many are listed


class PlcFunctions:
    """A channel's technology output, acknowledges and waits (GEO side)."""

    def __init__(self, config: PlcFunctionsConfig, spindle: Spindle,
                 plc_acknowledges: PlcConfig | None = None,
                 shown: ShowsUnit | None = None) -> None:
        self.config = config
        self.spindle = spindle
        # where the unit is kept: the channel's ``plc_functions`` part (one place)
        self._shown: ShowsUnit = shown if shown is not None else _OwnUnit()
        # [plc] acknowledges: (type, number) the real PLC acknowledges over ADS
        acks = plc_acknowledges or PlcConfig()
        self._plc_acks = frozenset({(TechnoType.M, n) for n in acks.numbers("M")}
                                   | {(TechnoType.H, n) for n in acks.numbers("H")})
        self.unit = PlcFunctionsUnit()
        self._extra: set[int] = set()  # ids of the pre/post blocks ``split`` made
        self._spindle_waits = False  # a spindle function waits for the spindle
        # MVS_SNS: id of a pre block -> the post block whose stop its output arms; armed
        # post blocks are stops only while an acknowledge is outstanding (issue 39)
        self._sns_post: dict[int, Block] = {}
        self._armed: list[Block] = []

    @property
    def unit(self) -> PlcFunctionsUnit:
        """What the PLC side reads (immutable; replaced on every change)."""
        return self._shown.plc_functions

    @unit.setter
    def unit(self, unit: PlcFunctionsUnit) -> None:
        self._shown.plc_functions = unit

    # -- decoder side -----------------------------------------------------------------

    def kind(self, type_: TechnoType, number: int) -> SyncKind:
        """The synchronisation kind of a function."""
        return self.config.kind(int(type_), number)

    def _functions(self, block: Block) -> list[tuple[TechnoType, int]]:
        out = [(TechnoType.M, m) for m in block.m_functions]
        out += [(TechnoType.H, h) for h in block.h_functions]
        if block.spindle_speed_rpm is not None:
            out.append((TechnoType.S, round(block.spindle_speed_rpm)))
        if block.tool is not None:
            out.append((TechnoType.T, block.tool))
        return out

    def split(self, block: Block) -> list[Block]:
        """The blocks the path runs for ``block`` (itself when nothing is to split)."""
        functions = self._functions(block)
        if not functions:
            return [block]
        kinds = [self.kind(t, n) for t, n in functions]
        if block.motion is None or block.needs_stop:
            # no motion (or a stop anyway): before and after are the same point
            if block.needs_stop or not any(k in _WAIT_BEFORE | _WAIT_AFTER for k in kinds):
                return [block]
            return [replace(block, stop=StopKind.TECHNOLOGY)]
        before = [f for f, k in zip(functions, kinds, strict=True) if k in _OUTPUT_BEFORE]
        after = [f for f, k in zip(functions, kinds, strict=True) if k == SyncKind.MNS_SNS]
        out: list[Block] = []
        if before:
            wait = any(k in _WAIT_BEFORE for k in kinds)
            out.append(self._part(block, before, wait))
        out.append(replace(block, m_functions=(), h_functions=(), spindle_speed_rpm=None,
                           tool=None))
        if after or any(k in _WAIT_AFTER for k in kinds):
            post = self._part(block, after, True)
            out.append(post)
            if before and not after:  # only MVS_SNS waits there: no stop once acknowledged
                self._sns_post[id(out[0])] = post
        return out

    def _part(self, block: Block, functions: list[tuple[TechnoType, int]], wait: bool) -> Block:
        ms = tuple(n for t, n in functions if t == TechnoType.M)
        hs = tuple(n for t, n in functions if t == TechnoType.H)
        s = next((float(n) for t, n in functions if t == TechnoType.S), None)
        tool = next((n for t, n in functions if t == TechnoType.T), None)
        part = replace(block, motion=None, m_functions=ms, h_functions=hs, spindle_speed_rpm=s,
                       tool=tool,
                       stop=StopKind.TECHNOLOGY if wait else StopKind.NONE)
        self._extra.add(id(part))
        return part

    # -- GEO side ---------------------------------------------------------------------

    def block_finished(self, block: Block, now_s: float) -> bool:
        """Output the technology of a block the path has reached the end of; True when
        it was a pre or post block of ``split``."""
        extra = id(block) in self._extra
        self._extra.discard(id(block))
        post = self._sns_post.pop(id(block), None)
        if post is not None:
            self._armed.append(post)
        elif self._armed and any(b is block for b in self._armed):
            # reached before the acknowledge: the path waits there (TECHNOLOGY), nothing
            # is left to release (no stale id may outlive the block)
            self._armed = [b for b in self._armed if b is not block]
        functions = self._functions(block)
        if functions:
            self._output(functions, now_s, block.spindle_pos_deg)
        return extra

    def _output(self, functions: list[tuple[TechnoType, int]], now_s: float,
                spindle_pos_deg: float | None = None) -> None:
        spindle_m = [n for t, n in functions if t == TechnoType.M and n in SPINDLE_M_FUNCTIONS]
        speed = next((n for t, n in functions if t == TechnoType.S), None)
        if spindle_m or speed is not None:
            self.spindle.command(spindle_m, speed, spindle_pos_deg)
            kinds = [self.kind(TechnoType.M, n) for n in spindle_m]
            if speed is not None:
                kinds.append(self.kind(TechnoType.S, speed))
            self._spindle_waits = any(k not in _NO_WAIT for k in kinds)
        units = list(self.unit.units)
        count = self.unit.output_count
        coolant = self.unit.coolant
        for type_, number in functions:
            if type_ == TechnoType.M and number in _COOLANT:
                coolant = _COOLANT[number](coolant)
        for type_, number in functions:
            if type_ == TechnoType.M and number in SPINDLE_M_FUNCTIONS:
                continue  # acknowledged by the spindle
            sync = self.kind(type_, number)
            if sync == SyncKind.NO_SYNCH:
                continue
            # S is acknowledged by the spindle: listed for the PLC as information
            acked = sync == SyncKind.MOS or type_ == TechnoType.S
            due = None
            if (not acked and self.config.auto_acknowledge
                    and (type_, number) not in self._plc_acks):
                due = now_s + self.config.prozess_zeit_s(int(type_), number)
            units.append(TechnoUnit(type_, number, sync, now_s, acked, due))
            count += 1
        while len(units) > UNITS_KEPT and not units[0].pending:
            units.pop(0)
        self.unit = PlcFunctionsUnit(tuple(units), count, coolant)

    def tick(self, now_s: float, cycle_s: float) -> None:
        """One cycle: the embedded PLC acknowledges what is due, the spindle ramps."""
        self.spindle.tick(cycle_s)
        units = self.unit.units
        if any(u.pending and u.ack_due_s is not None and u.ack_due_s <= now_s + 1e-12
               for u in units):
            self.unit = replace(self.unit, units=tuple(
                replace(u, acknowledged=True)
                if u.pending and u.ack_due_s is not None and u.ack_due_s <= now_s + 1e-12
                else u for u in units))

    def acknowledge(self, index: int) -> str | None:
        """The PLC acknowledges unit ``index``; why not, or None when done."""
        units = self.unit.units
        if not 0 <= index < len(units):
            return f"technology unit {index} does not exist ({len(units)} listed)"
        if not units[index].pending:
            return f"technology unit {index} is not waiting for an acknowledge"
        done = replace(units[index], acknowledged=True)
        self.unit = replace(self.unit, units=units[:index] + (done,) + units[index + 1:])
        return None

    @property
    def waits_for_spindle(self) -> bool:
        """A spindle function of the last output waits for the spindle (not there yet)."""
        return self._spindle_waits and not self.spindle.reached

    @property
    def waits_for_plc(self) -> bool:
        """An output function waits for the PLC's acknowledge."""
        return any(u.pending for u in self.unit.units)

    def all_acknowledged(self) -> bool:
        """Nothing the path must wait for: every unit acknowledged, the spindle there."""
        if self._spindle_waits and not self.spindle.reached:
            return False
        self._spindle_waits = False
        return not any(u.pending for u in self.unit.units)

    @property
    def stops_due(self) -> bool:
        """``stops_to_release`` has blocks for the next cycle (it must be stepped)."""
        return bool(self._armed) and not (self.waits_for_spindle or self.waits_for_plc)

    def stops_to_release(self) -> list[Block]:
        """Post blocks of MVS_SNS functions already output whose acknowledge has come:
        their block end is no stop any more (ISG: the path stops at the end of the
        block only when the acknowledge is late)."""
        if not self._armed or not self.all_acknowledged():
            return []
        armed, self._armed = self._armed, []
        return armed

    def reset(self) -> None:
        """RESET or ERROR of the channel: pending functions are dropped (as
        acknowledged: nothing waits for them any more) and the spindle brakes to a stop
        (``Spindle.stop``)."""
        self.spindle.stop()
        self.unit = PlcFunctionsUnit(
            tuple(replace(u, acknowledged=True) for u in self.unit.units),
            self.unit.output_count)
        self._extra.clear()
        self._sns_post.clear()
        self._armed.clear()
        self._spindle_waits = False


class ShowsUnit(Protocol):
    """Where the unit is kept: the channel's ``plc_functions`` part (``state.Channel``),
    which the snapshot shares; ``PlcFunctions`` keeps it nowhere else."""

    plc_functions: PlcFunctionsUnit


@dataclass(slots=True)
class _OwnUnit:
    """The place of the unit when no channel shows it (functions alone, in tests)."""

    plc_functions: PlcFunctionsUnit = PlcFunctionsUnit()


def show_technology(plc: PlcFunctions, now_s: float, cycle_s: float) -> bool:
    """One cycle of ``plc`` (acknowledges due, spindle ramp); True when its unit or
    spindle changed or the spindle still ramps."""
    unit, spindle = plc.unit, plc.spindle.state
    plc.tick(now_s, cycle_s)
    return unit is not plc.unit or spindle is not plc.spindle.state or not plc.spindle.reached
