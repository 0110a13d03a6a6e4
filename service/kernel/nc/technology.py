"""High-speed and kinematic settings a program switches, and what the decoder knows of
the channel around it (files, messages, the HSC programs).

``MachiningSettings`` is modal decoder state (part of ``ModalState``) and shown in the
channel's objects: ``#TRAFO ON/OFF``, ``#HSC ON [SURFACE PATH_DEV= TRACK_DEV=]``/``OFF``,
``#SLOPE [TYPE=STEP|TRAPEZ|HSC]``, ``#FILTER ON [AX_DEV=]``/``OFF``, ``G133 = <%>``
(acceleration weighting) and ``G134 = <%>`` (ramp time weighting). Their effect on the
motion is what the planner models: none of them changes the planned path or profile of
this kernel (its profile is the trapezoidal-acceleration one of the kernel issue); they
are decoded, checked and shown, so programs written for an ISG CNC run unchanged.
A program start resets them.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..path.kinematics import Kinematics

HSCS_MODES = ("DESELECT", "ROUGH", "PREFINISH", "FINISH")  # SysHscSettings @P1 = 1..4


@dataclass(slots=True)
class MachiningSettings:
    """Modal high-speed and transformation settings of a program."""

    trafo: bool = False  # #TRAFO ON
    ori_vector: bool = False  # #ORI MODE [VECTOR_2DOF]: under #TRAFO, A B C are a vector
    hsc: bool = False  # #HSC ON
    hsc_surface: bool = False  # #HSC ON [SURFACE]
    hsc_path_dev_mm: float = 0.0  # PATH_DEV (0: not programmed)
    hsc_track_dev_mm: float = 0.0  # TRACK_DEV
    slope: str = "TRAPEZ"  # #SLOPE [TYPE=..]; TRAPEZ is ISG's default profile
    filter: bool = False  # #FILTER ON
    filter_ax_dev_mm: float = 0.0  # AX_DEV
    acc_weight_pct: float = 100.0  # G133
    ramp_weight_pct: float = 100.0  # G134


@dataclass(frozen=True, slots=True)
class HscProgram:
    """One mode of the channel parameters ``hscs.<mode>.prog`` / ``.tolerance``."""

    prog: str = ""
    tolerance_mm: float = 0.0


def _ignore(*_args: object) -> None:
    return None


class OutputLimitReached(ValueError):
    """A file an NC program writes would pass a limit of the output area; ``limit`` is
    the ``[limits]`` key (``output_max_file_bytes``, ...), the message says by how much.
    The program stops with ``OUTPUT_LIMIT_REACHED`` at the statement that wrote."""

    def __init__(self, limit: str, message: str) -> None:
        super().__init__(message)
        self.limit = limit


@dataclass(frozen=True, slots=True)
class Surroundings:
    """What the decoder may reach outside the program text.

    ``write_file(name, text, replace)`` writes a file of the output area (``#MSG SAVE``,
    a cycle's result; never the program store): it queues the text and returns at once,
    or raises ``OutputLimitReached``; ``show_message(text)`` puts a ``#MSG`` into the
    channel's message list; ``hscs`` maps a mode of ``HSCS_MODES`` to its program and
    tolerance; ``kinematic_chain``: the channel's kinematics (``#TRAFO ON`` and the
    cycles that turn the tool need it); ``idle_steps_max``: steps of work without a block before
    the endless-program guard ends the decoding (``work_guard``, ``[limits]
    decoder_idle_steps_max``). The defaults drop files and messages.
    """

    write_file: Callable[[str, str, bool], None] = _ignore
    show_message: Callable[[str], None] = _ignore
    hscs: Mapping[str, HscProgram] = field(default_factory=dict)
    # the channel's five-axis kinematics (#TRAFO ON turns tip and orientation into axis
    # positions with it); None: a three-axis channel, #TRAFO is the identity
    kinematic_chain: Kinematics | None = None
    idle_steps_max: int | None = None  # the endless-program guard; None: IDLE_STEPS_MAX
    # P-CHAN-00041: whether M<i> has a synchronisation kind (an M the channel's list
    # lacks is ISG's unknown M function, 20160); None: every M is known
    m_function_known: Callable[[int], bool] | None = None
