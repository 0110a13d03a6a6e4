"""The running decoder as the statement runners see it.

The control flow (``control``), the ``#VAR`` blocks (``declarations``) and the contour
commands (``contour_run``, ``rt_loop_markers``) act on the decoder that runs them: its
frames, its modal state, its variables. They are below ``decoder`` (which imports them),
so they name the decoder by this protocol instead of importing the ``Decoder`` class;
``decoder.Decoder`` satisfies it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from .blockexec import BlockExecutor
from .call_stack import CallFrame
from .check import SyntaxCheck
from .evaluation import Env
from .modal import ModalState
from .parser import LineParser
from .program import Program
from .statements import Control
from .technology import Surroundings
from .variables import Value


class RunningDecoder(Env, Protocol):
    """What a statement runner reads and changes of the decoder running it.

    As an ``Env`` it also evaluates expressions (``find_variable``).
    """

    frames: list[CallFrame]  # the call frames, the running one last
    manual: bool  # decoding a manual block (MDI), not a program
    contour_lookahead: bool  # the channel has FCT_CONTOUR_LAH (P-CHAN-00650)
    own_variables: set[int]  # ids of the variables this decoder declared
    cancelled: Callable[[], bool]  # True once the run is cancelled (RESET)

    @property
    def modal(self) -> ModalState:
        """The modal state, changed as decoding goes."""

    def declare_block(self, frame: CallFrame, stmt: Control, after: int) -> None:
        """Run the ``#VAR`` block at ``frame.index``."""


class CallingDecoder(RunningDecoder, Protocol):
    """What the instruction runners (``instruction_run``) and the cycle calls
    (``cycle_run``, the built-in cycles) use besides: the channel's axes, the syntax
    check, the surroundings and the (sub)programs they load and push."""

    axes: tuple[str, ...]  # the channel's axis names
    check: SyntaxCheck | None  # the running syntax check, None when the program runs
    surroundings: Surroundings  # the file store and settings outside the program
    files_written: set[str]  # #MSG SAVE files written in this run
    parser: LineParser  # parses the lines of the programs it loads
    executor: BlockExecutor  # the modal state's block executor (tool radius, ...)

    def load(self, name: str) -> Program:
        """File ``name`` of the program store, parsed lazily (KeyError if absent)."""

    def has_file(self, name: str) -> bool:
        """Whether the program store holds file ``name``."""

    def push_cycle(self, frame: CallFrame, params: dict[int, Value] | None) -> None:
        """Run ``frame`` as a cycle with its ``@P`` parameters."""
