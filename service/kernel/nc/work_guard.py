"""The decoder's work counter: RESET within bounded work, and the endless-program guard.

The decoder counts its work in steps: one per line the general path runs (a statement,
a call, a return, a label line, a jump, a loop test) and one per line the hot path takes
without producing a block (a line of modal words only, such as ``N10`` or ``F500``).
A line that yields a block is no step of idle work: it goes to the consumer, which looks
for a RESET at every block it takes.

Every ``LOOK_EVERY_STEPS`` steps the decoding loop looks at the run (``look``):

- cancelled (RESET): ``DecodingCancelled`` ends the decoding at once, whatever the
  program does: loops, calls nested 19 deep, 90 000 labels and a backward ``$GOTO``;
  a step costs microseconds, so a RESET ends any program within milliseconds of kernel
  time, not at the next loop pass;
- ``idle_steps_max`` steps since the last block (motion or any other block; real-time
  loop markers are not blocks of the program): ``ENDLESS_LOOP`` (20226, "endless program"), at the line
  the decoder is at. A program that does nothing but compute, call, jump or send
  ``#MSG`` texts ends there, loops or not; one that produces blocks runs as long as the
  channel takes them (``$WHILE 1`` with motion runs until RESET, as on a real CNC).

Why steps and not time: the count is the same on every machine and under every load, so
the guard trips at the same line every time (the syntax check finds what a run finds).
The counter is a local integer of the generated loop (``fastpath``): it costs one
addition per step and one comparison, measured as no change of the decoder's speed.
"""

from __future__ import annotations

from .errors import NcError, NcErrorId
from .source import SourceText

#: steps between two looks at the run (RESET, the guard): a RESET waits at most this
#: many steps (about 5 ms of the general path on a loaded machine)
LOOK_EVERY_STEPS = 256
#: steps without a block before ENDLESS_LOOP (20226); ``[limits] decoder_idle_steps_max``
IDLE_STEPS_MAX = 1_000_000


def endless_program(src: SourceText, file: str, index: int, limit: int) -> NcError:
    """The ENDLESS_PROGRAM error at line ``index`` (0-based) of ``src``: its first
    non-blank character, or the last line when the decoder stands at the text's end."""
    index = min(max(index, 0), src.count - 1)
    text = src.line(index)
    column = len(text) - len(text.lstrip()) + 1
    return NcError(NcErrorId.ENDLESS_LOOP, file, index + 1, column,
                   f"endless program: {limit} steps without a motion or other block "
                   "([limits] decoder_idle_steps_max)")
