"""The channel's spindle: M3/M4/M5/M19 and S, override, commanded and actual speed.

ISG: "spindle rotation is activated if M03 or M04 is programmed and a valid speed is
set"; S alone stores the speed; M05 is the state after start-up. The actual speed
follows the commanded one (S x override, limited to the spindle's maximum) with the
spindle's acceleration (P-AXIS-00008 ``getriebe[i].dynamik.a_max``, degrees/s^2).
M19 orients to ``S.POS`` of its block (``M19 S.POS=90``; 0 degrees without it): the
spindle brakes to standstill and is then at its position. ``reached`` is the spindle's
own acknowledge of the last function (speed reached, stopped, oriented).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from cnc_objects.protocol.values import SPINDLE_M_FUNCTIONS as SPINDLE_M_FUNCTIONS
from cnc_objects.protocol.values import SpindleM as SpindleM
from cnc_objects.protocol.values import SpindleMode

from ..machine_config import SpindleConfig

__all__ = [  # SpindleMode is the value set of protocol.values, used here
    "DEG_S2_PER_RPM_S", "OVERRIDE_MAX", "SPINDLE_M_FUNCTIONS", "Spindle", "SpindleM",
    "SpindleMode", "SpindleState",
]

DEG_S2_PER_RPM_S = 6.0  # 1 rpm/s = 360 degrees / 60 s per s


_MODE_OF = {SpindleM.CW: SpindleMode.M03, SpindleM.CCW: SpindleMode.M04,
            SpindleM.STOP: SpindleMode.M05, SpindleM.ORIENT: SpindleMode.M19}
OVERRIDE_MAX = 1500  # 0.1 %: the largest spindle override accepted


@dataclass(frozen=True, slots=True)
class SpindleState:
    """What the objects show of the spindle; replaced when anything changes."""

    name: str = "S"
    mode: SpindleMode = SpindleMode.M05
    programmed_rpm: float = 0.0  # last S
    override: int = 1000  # 0.1 %
    commanded_rpm: float = 0.0  # signed target: + M3, - M4, 0 M5/M19
    actual_rpm: float = 0.0  # signed, follows commanded with the ramp
    position_deg: float = 0.0  # after M19
    reached: bool = True  # actual == commanded (M19: oriented)


class ShowsSpindle(Protocol):
    """Where a spindle keeps its state: the channel's ``spindle`` part
    (``state.Channel``), which the snapshot shares; the spindle writes nothing else."""

    spindle: SpindleState


@dataclass(slots=True)
class _OwnState:
    """The place of a spindle's state when no channel shows it (a spindle alone)."""

    spindle: SpindleState


class Spindle:
    """One spindle's commands and ramp (GEO side). Its state is kept in ``shown`` (the
    channel's ``spindle`` part): one place, so the channel never shows an old copy."""

    def __init__(self, config: SpindleConfig, shown: ShowsSpindle | None = None) -> None:
        self.config = config
        self.acc_rpm_s = config.a_max / DEG_S2_PER_RPM_S
        initial = SpindleState(name=config.bezeichnung)
        if shown is None:
            shown = _OwnState(initial)
        else:
            shown.spindle = initial
        self._shown = shown
        self._orient_deg = 0.0  # S.POS of the last M19

    @property
    def state(self) -> SpindleState:
        """The spindle's state (immutable; replaced on every change)."""
        return self._shown.spindle

    @state.setter
    def state(self, state: SpindleState) -> None:
        self._shown.spindle = state

    @property
    def reached(self) -> bool:
        """The spindle has done what was commanded last."""
        return self.state.reached

    def command(self, m_functions: list[int], speed_rpm: int | None,
                position_deg: float | None = None) -> None:
        """Apply the spindle M functions and S of one block (M19 > M3/M4/M5 > S);
        ``position_deg``: the block's S.POS, where an M19 orients to (default 0)."""
        if SpindleM.ORIENT in m_functions and position_deg is not None:
            self._orient_deg = position_deg  # modal (ISG): the last POS, 0 at start-up
        st = self.state
        programmed = st.programmed_rpm if speed_rpm is None else float(speed_rpm)
        mode = st.mode
        for m in sorted(m_functions, key=lambda n: n != SpindleM.ORIENT):
            mode = _MODE_OF[SpindleM(m)]
            break
        self._set(mode, programmed, st.override)

    def stop(self) -> None:
        """RESET or ERROR of the channel: M05, braking with the spindle's ramp (ISG
        P-AXIS-00455: a spindle turning by M3, M4 or M19 is stopped at a channel reset,
        unless ``no_stop_by_channel_reset`` is set). S stays stored."""
        st = self.state
        if self.config.no_stop_by_channel_reset or st.mode == SpindleMode.M05:
            return
        self._set(SpindleMode.M05, st.programmed_rpm, st.override)

    def set_override(self, override: int) -> str | None:
        """Spindle override in 0.1 %; why not, or None."""
        if not 0 <= override <= OVERRIDE_MAX:
            return f"spindle override {override / 10:g} % is outside 0..{OVERRIDE_MAX / 10:g} %"
        st = self.state
        self._set(st.mode, st.programmed_rpm, override)
        return None

    def _set(self, mode: SpindleMode, programmed_rpm: float, override: int) -> None:
        target = min(programmed_rpm * override / 1000.0, self.config.max_rpm)
        sign = {SpindleMode.M03: 1.0, SpindleMode.M04: -1.0}.get(mode, 0.0)
        commanded = sign * target
        st = self.state
        self.state = SpindleState(st.name, mode, programmed_rpm, override, commanded,
                                  st.actual_rpm, st.position_deg,
                                  st.actual_rpm == commanded and mode != SpindleMode.M19)

    def tick(self, cycle_s: float) -> None:
        """One cycle of the ramp."""
        st = self.state
        if st.reached:
            return
        step = self.acc_rpm_s * cycle_s
        diff = st.commanded_rpm - st.actual_rpm
        actual = st.commanded_rpm if abs(diff) <= step else st.actual_rpm + step * (
            1.0 if diff > 0 else -1.0)
        reached = actual == st.commanded_rpm
        position = st.position_deg
        if st.mode == SpindleMode.M19 and reached:
            position = self._orient_deg  # S.POS (default 0 degrees): oriented at standstill
        self.state = SpindleState(st.name, st.mode, st.programmed_rpm, st.override,
                                  st.commanded_rpm, actual, position, reached)
