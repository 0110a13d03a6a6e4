"""Manual mode of one channel: continuous jog, incremental jog, handwheel, homing by object.

ISG's manual mode (channel mode MANUAL, HLI ``hb_display_r``): each axis of the channel
has an operation mode (``ManualOperationMode``: handwheel, continuous jog, jog by
increments) and moves on its own, at the jog speed of its axis parameters (the rapid
key selects the rapid jog speed), under its acceleration, and never past a software
limit: a jog that reaches one stops there, sets the axis's limit warning and lists a
warning in the channel's error list.

The channel's state follows ISG's states of manual mode: SELECTED (nothing to do),
ACTIVE while an axis moves, READY when the motions are over, HOLD after a feedhold (the
axes brake; START ends the hold), ERROR only through RESET-able errors of other sources.
Jogging is refused (``Refusal`` NOT_READY, ADS 0x707, with the reason) when the channel
is not in MANUAL, is in HOLD or ERROR, or the axis is not linked to its drive.
Out-of-range values are refused as INVALID_VALUE (ADS 0x706).

In a program, ISG's G200/G201 enable manual mode for named axes (``program_request``):
their manual motions then move a *manual offset* that the path's output adds to the
axis (``offsets_mm``), inside the software limits of the sum; G200 while the program
waits at its block (START ends it), G201 in parallel to the path until G202. The offsets
last until the program ends (ISG: G202 does not clear them); a new start takes the axes
where they stand.

``ManualMode.cycle`` runs in the GEO cycle (``ChannelRunner.cycle``), before the drives
follow the axes; ``offset_cycle`` is its twin for G200/G201, before the path's step.
What HMI and PLC read is ``Channel.manual``: one immutable ``ManualAxisView`` per axis,
replaced when something changes.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from enum import IntEnum

from cnc_objects.protocol.units import UM01_PER_MM
from cnc_objects.protocol.values import WORKING_STATES, ManualOperationMode

from ..machine_config import MachineConfig, ManualAxisConfig
from .axis_params import AxisParameters, monitored_limits_mm
from .channel_mode import ChannelMode, ChannelState, describe
from .channel_transitions import ChannelEvent, allowed
from .homing import HomingState
from .manual_motion import AxisDynamicsLimits, AxisMotion
from .manual_view import DisplayState, ManualAxisView
from .nc.blocks import ManualModeKind, ManualModeRequest
from .refusal import Refusal, RefusalReason
from .state import Channel, ErrorEntry

INCREMENT_MIN_01UM = 1  # 0.1 um: the smallest jog increment
INCREMENT_MAX_01UM = 100_000  # 10 mm: the largest jog increment
RESOLUTION_MIN_01UM, RESOLUTION_MAX_01UM = 1, 100_000  # handwheel path per pulse, 0.1 um


class ManualErrorId(IntEnum):
    """Ids of the warnings manual mode lists (project ids, as AxisErrorId's)."""

    SW_LIMIT_REACHED = 70910  # a manual motion stopped at a software limit


@dataclass(slots=True)
class _Axis:
    """Manual state of one axis of the channel (the view is made from it)."""

    number: int  # logical axis number
    config: ManualAxisConfig
    operation_mode: int = ManualOperationMode.NONE
    hr_aufloesung: int = 10
    increment_01um: int = UM01_PER_MM
    rapid: bool = False
    handwheel_counter: int = 0
    jog_plus: bool = False
    jog_minus: bool = False
    limit_warning: bool = False
    motion: AxisMotion | None = None
    homing: HomingState | None = None
    program: ManualModeKind | None = None  # G200 / G201 enabled manual mode in a program
    offset_mm: float = 0.0  # manual offset summed in a program (G200/G201)


def _s32_delta(new: int, old: int) -> int:
    """new - old of a 32-bit counter that may wrap around."""
    return ((new - old + 0x8000_0000) & 0xFFFF_FFFF) - 0x8000_0000


class ManualMode:
    """The manual motions of one channel's axes."""

    def __init__(self, channel: Channel, machine: MachineConfig,
                 params: dict[int, AxisParameters], cycle_s: float,
                 move: Callable[[ChannelEvent], None],
                 report: Callable[[ErrorEntry], None]) -> None:
        """``move`` changes the channel's state (``ChannelRunner._move``); ``report``
        lists a warning; ``params`` are the kernel's effective axis parameters."""
        self._channel = channel
        self._params = params
        self._cycle_s = cycle_s
        self._move = move
        self._report = report
        self._axes: list[_Axis] = []
        # the manual offsets the path's output adds; None while all are 0 (no cost)
        self.offsets_mm: tuple[float, ...] | None = None
        # P-AXIS-00277 of the axes that leave it out (issue 39)
        self._requires_homing_default = machine.programs_need_referenced_axes
        for axis in channel.axes:
            configured = machine.axis(axis.logical_number)
            config = configured.manual if configured is not None else ManualAxisConfig()
            self._axes.append(_Axis(axis.logical_number, config,
                                    hr_aufloesung=config.handwheel_resolution_incr))
        self.publish()

    # ------------------------------------------------------------ queries

    @property
    def engaged(self) -> bool:
        """Manual mode works the channel now (MANUAL, ACTIVE or HOLD)."""
        ch = self._channel
        return ch.mode == ChannelMode.MANUAL and ch.state in WORKING_STATES

    @property
    def in_program(self) -> bool:
        """G200/G201 enabled manual mode for an axis of the running program."""
        return any(a.program is not None for a in self._axes)

    def program_motion(self) -> str | None:
        """The name of an axis whose G200/G201 manual motion still runs, or None."""
        for k, axis in enumerate(self._axes):
            if axis.program is not None and axis.motion is not None:
                return self._channel.axes[k].name
        return None

    def referenced(self, axis_index: int) -> bool:
        """The axis at ``axis_index`` of the channel has been homed."""
        homing = self._axes[axis_index].homing
        return homing is not None and homing.referenced

    def homing_table(self) -> dict[int, tuple[float, float]]:
        """For G74: axis index -> (reference position mm, homing speed mm/s)."""
        return {k: (a.config.pos_refpkt_mm, a.config.homing_vel_mm_s)
                for k, a in enumerate(self._axes)}

    def requires_homing(self, axis_index: int) -> bool:
        """P-AXIS-00277 ``prog_move_requires_homing`` of the axis: a program may move it
        only once it is referenced (the machine's default when the axis leaves it out)."""
        own = self._axes[axis_index].config.prog_move_requires_homing
        return self._requires_homing_default if own is None else own

    def locked_axes(self) -> frozenset[int]:
        """Indices of the axes a program must not move now: they need homing
        (P-AXIS-00277) and are not referenced."""
        return frozenset(k for k in range(len(self._axes))
                         if self.requires_homing(k) and not self.referenced(k))

    def unreferenced_axes(self) -> list[str]:
        """Names of the channel's axes that are not referenced."""
        return [a.name for k, a in enumerate(self._channel.axes) if not self.referenced(k)]

    # ------------------------------------------------------------ commands (cycle thread)

    def set_operation_mode(self, axis_index: int, value: int) -> Refusal | None:
        """``manual_operation_mode_w``: 0 none, 1 handwheel, 2 continuous, 3 increments."""
        if value not in ManualOperationMode._value2member_map_:
            return _invalid(f"operation mode {value} is not one of "
                            + ", ".join(f"{m.value} {m.name}" for m in ManualOperationMode))
        axis = self._axes[axis_index]
        if axis.motion is not None:
            return self._not_ready(axis_index, "change the operation mode at standstill")
        axis.operation_mode = value
        self.publish()
        return None

    def set_increment(self, axis_index: int, value: int) -> Refusal | None:
        """``manual_increment_w``: the jog increment in 0.1 um (0.1 um .. 10 mm)."""
        if not INCREMENT_MIN_01UM <= value <= INCREMENT_MAX_01UM:
            return _invalid(f"jog increment {value} (0.1 um) is outside {INCREMENT_MIN_01UM}.."
                            f"{INCREMENT_MAX_01UM} (0.1 um .. 10 mm)")
        self._axes[axis_index].increment_01um = value
        self.publish()
        return None

    def set_resolution(self, axis_index: int, value: int) -> Refusal | None:
        """``manual_hr_aufloesung_w``: handwheel path per pulse in 0.1 um."""
        if not RESOLUTION_MIN_01UM <= value <= RESOLUTION_MAX_01UM:
            return _invalid(f"handwheel resolution {value} (0.1 um per pulse) is outside "
                            f"{RESOLUTION_MIN_01UM}..{RESOLUTION_MAX_01UM}")
        self._axes[axis_index].hr_aufloesung = value
        self.publish()
        return None

    def set_rapid(self, axis_index: int, value: bool) -> Refusal | None:
        """``manual_rapid_w``: TRUE jogs at the rapid jog speed (from the next jog)."""
        self._axes[axis_index].rapid = bool(value)
        self.publish()
        return None

    def jog(self, axis_index: int, direction: int, pressed: bool) -> Refusal | None:
        """``manual_jog_plus_w`` / ``manual_jog_minus_w``: the key pressed (TRUE) or
        released (FALSE). Continuous: moves while pressed; increments: one increment per
        press. TRUE while the key is pressed changes nothing (a client renews its hold
        so, ``service.jog_holds``) unless a continuous jog was stopped by something else
        than the limit (feedhold, drive given up): that is a new press, checked as one.
        Releasing is always accepted."""
        axis = self._axes[axis_index]
        if pressed and (axis.jog_plus if direction > 0 else axis.jog_minus) and (
                axis.operation_mode != ManualOperationMode.CONTINUOUS
                or axis.motion is not None or axis.limit_warning):
            return None  # held already: a renewal of the service's dead-man, not a press
        if not pressed:
            self._set_key(axis, direction, False)
            if (axis.operation_mode == ManualOperationMode.CONTINUOUS
                    and axis.motion is not None and axis.motion.direction == direction):
                axis.motion.stop()
            self.publish()
            return None
        mode = axis.operation_mode
        if mode not in (ManualOperationMode.CONTINUOUS, ManualOperationMode.INCREMENTAL):
            why = ("the axis moves by the handwheel counter in handwheel mode"
                   if mode == ManualOperationMode.HANDWHEEL else
                   "select continuous (2) or incremental (3) jog with manual_operation_mode_w")
            return self._not_ready(axis_index, f"jog keys need a jog operation mode: {why}")
        refused = self._may_move(axis_index)
        if refused is not None:
            return refused
        self._set_key(axis, direction, True)
        motion = self._motion(axis_index, self._jog_vel(axis))
        if mode == ManualOperationMode.CONTINUOUS:
            motion.run(direction)
        else:
            motion.move_by(direction * axis.increment_01um / UM01_PER_MM)
        self._started(axis_index)
        return None

    def handwheel(self, axis_index: int, counter: int) -> Refusal | None:
        """``manual_handwheel_counter_w``: the PLC/HMI writes its counter; in handwheel
        mode the axis moves by (new - old) pulses times the resolution. Outside it the
        value is only taken (a PLC writes the counter every cycle)."""
        axis = self._axes[axis_index]
        pulses = _s32_delta(counter, axis.handwheel_counter)
        axis.handwheel_counter = counter
        if axis.operation_mode != ManualOperationMode.HANDWHEEL or pulses == 0:
            self.publish()
            return None
        refused = self._may_move(axis_index)
        if refused is not None:
            self.publish()
            return refused
        motion = self._motion(axis_index, self._jog_vel(axis))
        motion.move_by(pulses * axis.hr_aufloesung / UM01_PER_MM)
        self._started(axis_index)
        return None

    def start_homing(self, axis_index: int) -> Refusal | None:
        """``homing_start_w``: the homing run of the axis (MANUAL mode)."""
        refused = self._may_move(axis_index)
        if refused is not None:
            return refused
        axis = self._axes[axis_index]
        if axis.motion is not None:
            return self._not_ready(axis_index, "start homing at standstill")
        axis.homing = HomingState(referenced=False, active=True)
        motion = self._motion(axis_index, axis.config.homing_vel_mm_s)
        motion.move_to(axis.config.pos_refpkt_mm)
        self._started(axis_index)
        return None

    def program_request(self, request: ManualModeRequest) -> None:
        """A G200/G201/G202 block reached by the path: manual mode on or off for its
        axes (G202 brakes their manual motions; the offsets stay)."""
        enable = None if request.kind == ManualModeKind.G202 else request.kind
        for k in request.axes:
            axis = self._axes[k]
            axis.program = enable
            if enable is None and axis.motion is not None:
                axis.motion.stop()
        self.publish()

    def end_g200(self) -> None:
        """START after G200 ("continue motion"): manual mode ends for every axis G200
        enabled."""
        for axis in self._axes:
            if axis.program == ManualModeKind.G200:
                axis.program = None
        self.publish()

    def clear_program(self) -> None:
        """A run begins or ends (or RESET): no axis is in G200/G201, and the offsets are
        0 (the axes stand where path plus offset put them; a new run starts from there)."""
        for axis in self._axes:
            if axis.program is not None:
                axis.motion = None
            axis.program = None
            axis.offset_mm = 0.0
        self.offsets_mm = None
        self.publish()

    def offset_cycle(self) -> bool:
        """One GEO cycle of the G200/G201 manual motions (before the path's step): each
        moves its axis's offset, inside the software limits of path + offset. True while
        one moves."""
        ch = self._channel
        moving = False
        for k, axis in enumerate(self._axes):
            motion = axis.motion
            if motion is None or axis.program is None:
                continue
            self._offset_limits(k, motion)
            path_mm = ch.axes[k].position_mm - axis.offset_mm
            axis.offset_mm = motion.step(self._cycle_s)
            if motion.hit_limit and not axis.limit_warning:
                axis.limit_warning = True
                self._warn_limit(k, path_mm + axis.offset_mm)
            if motion.at_rest:
                axis.motion = None
            else:
                moving = True
        offsets = tuple(a.offset_mm for a in self._axes)
        self.offsets_mm = offsets if any(offsets) else None
        self.publish()
        return moving

    def feedhold(self) -> None:
        """HOLD: every manual motion brakes; the goals are dropped."""
        for axis in self._axes:
            if axis.motion is not None:
                axis.motion.stop()
            if axis.homing is not None and axis.homing.active:
                axis.homing = HomingState(referenced=False, active=False)
        self.publish()

    def stop_at_once(self) -> None:
        """RESET: the motions end where the axes are (the keys count as released)."""
        for axis in self._axes:
            axis.motion = None
            axis.jog_plus = axis.jog_minus = False
            axis.limit_warning = False
            if axis.homing is not None and axis.homing.active:
                axis.homing = HomingState(referenced=False, active=False)
        self.publish()

    def mark_referenced(self, axis_index: int) -> None:
        """The axis was homed by G74 in a program."""
        self._axes[axis_index].homing = HomingState(referenced=True, active=False)
        self.publish()

    # ------------------------------------------------------------ cycle

    def cycle(self) -> bool:
        """One GEO cycle of the manual motions; True while an axis moves. The channel
        goes from ACTIVE to READY when all motions are over (HOLD stays HOLD)."""
        ch = self._channel
        moving = False
        for k, axis in enumerate(self._axes):
            motion = axis.motion
            if motion is None:
                continue
            logical = ch.axes[k]
            if ch.suspend.output_suspended or not (logical.actual_link or logical.released):
                axis.motion = None  # the drive was given up (jog of path): the axis stands
                continue
            position = motion.step(self._cycle_s)
            # the drive follows the step (KernelState.drive_axes)
            logical.command_position_01um = round(position * UM01_PER_MM)
            logical.position_mm = logical.command_position_01um / UM01_PER_MM
            if motion.hit_limit and not axis.limit_warning:
                axis.limit_warning = True
                self._warn_limit(k, position)
            if motion.at_rest:
                axis.motion = None
                if axis.homing is not None and axis.homing.active:
                    axis.homing = HomingState(referenced=True, active=False)
            else:
                moving = True
        if not moving and ch.state == ChannelState.ACTIVE:
            self._move(ChannelEvent.PROGRAM_END)
        self.publish()
        return moving

    def publish(self) -> None:
        """Show the axes' manual state in ``Channel.manual``."""
        self._channel.manual = tuple(self._view(axis) for axis in self._axes)

    # ------------------------------------------------------------ helpers

    def _view(self, axis: _Axis) -> ManualAxisView:
        manual = self._channel.mode == ChannelMode.MANUAL or axis.program is not None
        state = DisplayState.DEACTIVATED
        if manual:
            state = (DisplayState.ASSIGNED if axis.operation_mode != ManualOperationMode.NONE
                     else DisplayState.ENABLED)
        motion, homing = axis.motion, axis.homing
        return ManualAxisView(
            state=state, operation_mode=axis.operation_mode,
            control_element=1 if state == DisplayState.ASSIGNED else 0,
            hr_aufloesung=axis.hr_aufloesung,
            tipp_geschw_um_s=round(self._jog_vel(axis) * 1000),
            increment_01um=axis.increment_01um, rapid=axis.rapid,
            handwheel_counter=axis.handwheel_counter,
            jog_plus=axis.jog_plus, jog_minus=axis.jog_minus,
            velocity_um_s=0.0 if motion is None else motion.velocity_mm_s * 1000,
            moving=motion is not None, limit_warning=axis.limit_warning,
            referenced=homing is not None and homing.referenced,
            homing_active=homing is not None and homing.active,
            offset_01um=round(axis.offset_mm * UM01_PER_MM),
        )

    def _jog_vel(self, axis: _Axis) -> float:
        """The jog speed in effect (mm/s): jog or rapid jog speed, feed override
        applied, capped at the axis's maximum velocity."""
        config = axis.config
        speed = config.jog_rapid_vel_mm_s if axis.rapid else config.jog_vel_mm_s
        speed *= self._channel.switches.feed_override_per_mille / 1000
        return min(speed, self._params[axis.number].vel_max_mm_s)

    def _motion(self, axis_index: int, vel_mm_s: float) -> AxisMotion:
        """The axis's motion (a new one at its position), with the limits in force now."""
        axis = self._axes[axis_index]
        p = self._params[axis.number]
        low_mm, high_mm = monitored_limits_mm(p, self.referenced(axis_index))
        limits = AxisDynamicsLimits(max(vel_mm_s, 1e-6), p.acc_max_mm_s2, low_mm, high_mm)
        start_mm = self._channel.axes[axis_index].position_mm
        if axis.program is not None and self._channel.mode != ChannelMode.MANUAL:
            start_mm = axis.offset_mm  # G200/G201: the motion moves the manual offset
        if axis.motion is None:
            axis.motion = AxisMotion(start_mm, limits)
        else:
            axis.motion.limits = limits
        if axis.program is not None and self._channel.mode != ChannelMode.MANUAL:
            self._offset_limits(axis_index, axis.motion)
        return axis.motion

    def _offset_limits(self, axis_index: int, motion: AxisMotion) -> None:
        """The software limits of an offset motion: those of the axis, less where the
        path puts it now (G200's offset limits are the software limits, ISG)."""
        axis = self._axes[axis_index]
        p = self._params[axis.number]
        path_mm = self._channel.axes[axis_index].position_mm - axis.offset_mm
        low_mm, high_mm = monitored_limits_mm(p, self.referenced(axis_index))
        motion.limits = replace(motion.limits, sw_limit_min_mm=low_mm - path_mm,
                                sw_limit_max_mm=high_mm - path_mm)

    def _started(self, axis_index: int) -> None:
        """A motion began: the channel works (ACTIVE); a goal cut at a limit warns now."""
        ch = self._channel
        if ch.state != ChannelState.ACTIVE and ch.mode == ChannelMode.MANUAL:
            self._move(ChannelEvent.START)
        axis = self._axes[axis_index]
        motion = axis.motion
        if motion is not None and motion.hit_limit:  # the goal was cut at a limit
            if not axis.limit_warning:
                self._warn_limit(axis_index, motion.target_mm)
            axis.limit_warning = True
        else:
            axis.limit_warning = False
        self.publish()

    def _may_move(self, axis_index: int) -> Refusal | None:
        """Why the axis cannot start a manual motion now, or None."""
        ch = self._channel
        program = self._axes[axis_index].program
        if ch.mode != ChannelMode.MANUAL and program is None:
            return self._not_ready(axis_index, "manual motion needs channel mode MANUAL (4) "
                                   "(select it with mc_command_mode_w), or G200/G201 for the "
                                   "axis in the running program")
        if program is not None and ch.mode != ChannelMode.MANUAL:
            if ch.state != ChannelState.ACTIVE:
                return self._not_ready(axis_index, f"{program.name} manual mode moves only "
                                       "while the program runs (ACTIVE); START first")
            logical = ch.axes[axis_index]
            if ch.suspend.output_suspended or (not logical.actual_link and not logical.released):
                return self._not_ready(axis_index, "the axis is not linked to its drive")
            return None
        if ch.state == ChannelState.HOLD:
            return self._not_ready(axis_index, "manual mode is held (feedhold); START or "
                                   "RESET first")
        if ch.state != ChannelState.ACTIVE and not allowed(ch.state, ChannelEvent.START):
            return self._not_ready(axis_index, "RESET clears the error first")
        logical = ch.axes[axis_index]
        if ch.suspend.output_suspended or (not logical.actual_link and not logical.released):
            return self._not_ready(axis_index, "the axis is not linked to its drive")
        homing = self._axes[axis_index].homing
        if homing is not None and homing.active:
            return self._not_ready(axis_index, "the axis is homing")
        return None

    def _not_ready(self, axis_index: int, what: str) -> Refusal:
        ch = self._channel
        return Refusal(RefusalReason.NOT_READY,
                       f"channel {ch.channel_id} is {describe(ch.mode, ch.state)}, axis "
                       f"{ch.axes[axis_index].name}: {what}")

    @staticmethod
    def _set_key(axis: _Axis, direction: int, pressed: bool) -> None:
        if direction > 0:
            axis.jog_plus = pressed
        else:
            axis.jog_minus = pressed

    def _warn_limit(self, axis_index: int, position_mm: float | None) -> None:
        name = self._channel.axes[axis_index].name
        p = self._params[self._axes[axis_index].number]
        where = "" if position_mm is None else f" at {position_mm:g} mm"
        self._report(ErrorEntry(
            ManualErrorId.SW_LIMIT_REACHED,
            f"axis {name}: manual motion stopped at its software limit{where} "
            f"(limits {p.sw_limit_min_mm:g}..{p.sw_limit_max_mm:g} mm)", warning=True))


def _invalid(message: str) -> Refusal:
    return Refusal(RefusalReason.INVALID_VALUE, message)
