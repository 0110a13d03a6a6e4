"""What the kernel gives each of its channels' runners: ``RunnerServices``, one value
shared by all of them (``channel_run.ChannelRunner`` takes it with its channel)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from ..machine_config import MachineConfig
from .alarms import AlarmLog
from .axis_params import AxisParameters
from .nc.source import NcText
from .switchover import Switchover
from .syntax_check import CHECK_MAX_ERRORS
from .workers import Workers


def _write_nowhere(name: str, data: bytes, replace: bool = False) -> None:
    """A runner without an output area: its files are dropped."""


def _nothing() -> None:
    """Nothing to do while a cycle waits."""


@dataclass(frozen=True, slots=True)
class RunnerServices:
    """The machine, the program store, time, the shared kernel parts and the limits a
    channel's runner works with.

    ``params``: the kernel's effective axis parameters (read at each program start, so a
    parameter update applies from the next run); ``switchover`` links the channels' axes
    to the drives; ``deterministic``: virtual or stepped time, where a cycle waits for
    the decoder; ``files`` writes a channel's own files (logs, reports), ``save`` those
    its NC programs write, both into the output area (queued, never blocking the cycle);
    ``on_wait``: called while a cycle waits for the decoder or the check (virtual clock),
    so that the kernel answers the cycle's commands meanwhile; ``alarms``: the kernel's
    alarm log, which every listed error and warning is raised in; ``workers``: the
    kernel's worker registry, which runs the decoder and check threads;
    ``check_max_errors``: errors a syntax check keeps ([limits] check_max_errors), the
    rest are counted only; ``idle_steps_max``: the decoder's endless-program guard
    ([limits] decoder_idle_steps_max; None: ``nc.work_guard.IDLE_STEPS_MAX``)."""

    machine: MachineConfig
    loader: Callable[[str], NcText]  # a stored program's text by name
    exists: Callable[[str], bool]  # whether the store holds a program
    cycle_s: float
    deterministic: bool
    params: dict[int, AxisParameters]
    switchover: Switchover
    files: Callable[..., None] = _write_nowhere
    save: Callable[[str, bytes, bool], None] = _write_nowhere
    on_wait: Callable[[], None] = _nothing
    alarms: AlarmLog = field(default_factory=AlarmLog)
    workers: Workers = field(default_factory=Workers)
    check_max_errors: int = CHECK_MAX_ERRORS
    idle_steps_max: int | None = None
