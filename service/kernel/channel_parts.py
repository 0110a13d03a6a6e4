"""The immutable parts a channel is made of, each written by one owner.

A ``state.Channel`` holds its values in parts instead of 50 loose fields: a part is
immutable and replaced whole by the module that owns it, so the snapshot shares every
part that did not change (``Channel.frozen`` copies references, not values) and no
other module can change a value behind its owner's back. The owners (the only modules
that build or replace a part; ``tests/service/kernel/test_channel_parts.py`` checks it):

==================  =====================================================================
part                owner
==================  =====================================================================
``switches``        ``commands``, ``commands_operator`` (what operators and the PLC command)
``suspend``         ``commands`` (the PLC's unit), ``switchover`` (the output's state)
``program``         ``channel_run`` (select, start, messages), ``program_run``, ``channel_check``
``block``           ``program_run``, ``channel_check``, ``channel_run`` (its start)
``path``            ``program_run`` (each cycle of a run), ``channel_check``, ``channel_run``
``errors``          ``channel_run`` (``report``, RESET), ``channel_check`` (the check's count)
``manual``          ``manual_mode``: ``manual_view.ManualAxisView`` per axis
``tooling``         ``tooling``, ``channel_run``: ``tooling_view.ChannelTooling``
``tool_cut_cycles`` ``tool_life``, ``commands_tooling``
``contour``         ``commands`` (the PLC's request), ``channel_run``, ``program_run``
``spindle``         ``spindle.Spindle`` (its ``state`` is this part)
``plc_functions``   ``plc_functions.PlcFunctions`` (its ``unit`` is this part)
==================  =====================================================================

The parts a cycle replaces often (``path`` every cycle of a run, ``block`` at every block
end) are ``NamedTuple``: built by keyword in well under a microsecond. The others are
frozen dataclasses changed with ``dataclasses.replace``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

from cnc_objects.protocol.values import RapidOverrideMode

from ..machine_config import SyntaxCheckConfig
from .nc.technology import MachiningSettings


@dataclass(frozen=True, slots=True)
class ChannelSwitches:
    """What the operator (HMI) and the PLC command: overrides, execution mode, skip
    levels, single block, optional stop, the syntax check's parameters. Values in 0.1 %
    for overrides; ``*_plc_*`` are ISG control units (``gpCh[i].decoder_mc_control``)
    whose ``command_w`` counts while their ``enable_w`` is TRUE."""

    feed_override_max: int = 1000  # 0.1 %, from the configuration
    feed_override_command: int = 1000  # 0.1 %
    feed_override_per_mille: int = 1000  # 0.1 %, in effect
    rapid_override_command: int = 1000  # 0.1 %, mc_command_rapid_override_w
    rapid_override_per_mille: int = 1000  # 0.1 %, in effect on G0 (P-CHAN-00181 mode)
    g00_override_mode: int = RapidOverrideMode.ACTIVE  # P-CHAN-00181, from the configuration
    execution_mode_command: int = 0  # the HMI's request (ExecutionMode bits)
    execution_mode_plc_command: int = 0
    execution_mode_plc_enable: bool = False
    block_ignore_command: int = 0  # skip levels /1../10 (bit n-1), mc_command_block_ignore_w
    block_ignore_plc_command: int = 0
    block_ignore_plc_enable: bool = False
    single_block: bool = False
    m01_stop_enable: bool = False  # M1 stops only while TRUE (mc_command_M01_stop_enable_w)
    prod_time_trace: bool = False  # PROD_TIME runs write their path (ch<c>.prod_time_trace)
    syn_chk: SyntaxCheckConfig = field(default_factory=SyntaxCheckConfig)  # next check's

    @property
    def execution_mode_commanded(self) -> int:
        """The execution mode the next program start takes: the PLC's ``command_w``
        while it enables the unit, else the HMI's request."""
        if self.execution_mode_plc_enable:
            return self.execution_mode_plc_command
        return self.execution_mode_command

    @property
    def block_ignore_commanded(self) -> int:
        """The skip levels the next program start takes: the PLC's ``command_w`` while
        it enables the control unit, else the HMI's ``mc_command_block_ignore_w``."""
        if self.block_ignore_plc_enable:
            return self.block_ignore_plc_command
        return self.block_ignore_command


@dataclass(frozen=True, slots=True)
class SuspendUnit:
    """``gpCh[i].bahn_mc_control.suspend_axis_output`` (ISG control unit, see
    docs/jog-of-path.md) and whether the axes are given up now (its ``state_r``)."""

    command_w: bool = False
    enable_w: bool = True
    request_r: bool = False  # the CNC's own request (followed while enable_w is FALSE)
    output_suspended: bool = False  # state_r: the axes are given up

    @property
    def commanded(self) -> bool:
        """The value the unit commands: ``command_w`` while the PLC enables the unit,
        else the CNC's own request."""
        return self.command_w if self.enable_w else self.request_r


@dataclass(frozen=True, slots=True)
class ProgramShown:
    """The selected program and what its run shows beside the path."""

    program_name: str = ""  # selected program
    execution_mode_active: int = 0  # ExecutionMode bits the run was started with
    block_ignore_active: int = 0  # the skip mask the run was started with
    waiting_for_start: bool = False  # standing at M0/M1 or a single-block stop
    decoder_flags: int = 0  # state.DecoderFlag bits (pMC[i].StateDecoder_Data)
    # #MSG texts of the program, newest first (at most MESSAGES_LISTED), and their count
    messages: tuple[str, ...] = ()
    message_count: int = 0
    # #TRAFO/#HSC/#SLOPE/#FILTER/G133/G134 as decoded so far (nc.technology)
    machining: MachiningSettings = field(default_factory=MachiningSettings)


class BlockShown(NamedTuple):
    """The block in the interpolator, and the blocks counted since the start."""

    file_name: str = ""  # file of the block in the interpolator
    line: int = 0  # its line in file_name (1-based; 0 = none)
    file_offset: int = 0  # byte offset of its line in that file
    block_number: int = -1  # N of the block; -1 = none
    block_count: int = 0  # blocks finished since program start
    manual_blocks_done: int = 0  # manual blocks finished since the channel started


class PathShown(NamedTuple):
    """The path's values of the last cycle."""

    path_velocity_mm_s: float = 0.0
    programmed_velocity_mm_s: float = 0.0
    remaining_in_block_mm: float = 0.0
    dist_prog_start_01um: float = 0.0  # path distance since program start (0.1 um)
    program_time_s: float = 0.0  # kernel time since program start


@dataclass(frozen=True, slots=True)
class ChannelErrors:
    """The channel's errors, newest first (at most ``ERRORS_LISTED``), and how many
    arose since the last RESET."""

    entries: tuple[ErrorEntry, ...] = ()
    count: int = 0


BLOCK_START_COLUMN = 1  # the column of an error about a whole block: the block's start


@dataclass(frozen=True, slots=True)
class ErrorEntry:
    """An error of a channel: ISG-style id, text, and where in which NC file it arose.

    Lines and columns count from 1; 0 means none. An error about a whole block (not a word
    of it) is at the block's first column, ``BLOCK_START_COLUMN``."""

    id: int
    text: str
    file: str = ""
    line: int = 0
    column: int = 0
    warning: bool = False  # a warning is listed but does not stop the channel

    def __str__(self) -> str:
        where = f"{self.file}:{self.line}:{self.column}: " if self.file else ""
        kind = "warning" if self.warning else "error"
        return f"{kind} {self.id}: {where}{self.text}"
