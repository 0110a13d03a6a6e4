"""The operator's switches of a channel: rapid override, block skip, optional stop.

ISG sources (docs/kernel.md "Operator switches"):

- rapid override: P-CHAN-00181 ``g00_override_mode`` says how it acts on G0 blocks:
  NOT_USED the feed override acts on G0 too; MINIMUM_OF_G0_G1 the smaller of feed and
  rapid override; ACTIVE (and ACTIVE_EXTENDED) the rapid override alone. Feed blocks
  always take the feed override;
- block skip: ``mc_command_block_ignore_w`` (COM 0x4), a bit mask of the skip levels
  ``/1``..``/10`` (bit n-1; ``/`` alone is level 1), read at program start as the
  control unit ``gpCh[i].decoder_mc_control.program_block_ignore`` is;
- optional stop: M1 stops only while the switch is on (HLI control unit
  ``m01_stop_enable``, TwinSharp's ``mc_command_M01_stop_enable_w``); read when the
  block enters the look-ahead buffer.
"""

from __future__ import annotations

from dataclasses import replace

from cnc_objects.protocol.values import RapidOverrideMode

from .nc.blocks import Block, StopKind
from .refusal import Refusal, RefusalReason
from .state import Channel

RAPID_OVERRIDE_MAX = 1000  # 0.1 %: G0 never runs faster than the axes' rapid speed
SKIP_LEVELS_MASK = 0x3FF  # skip levels 1..10


def rapid_override_per_mille(ch: Channel) -> int:
    """The override G0 blocks run with (0.1 %), from the channel's g00_override_mode."""
    feed, rapid = ch.switches.feed_override_per_mille, ch.switches.rapid_override_command
    match ch.switches.g00_override_mode:
        case RapidOverrideMode.NOT_USED:
            return feed
        case RapidOverrideMode.MINIMUM_OF_G0_G1:
            return min(feed, rapid)
        case _:
            return rapid


def with_optional_stop(block: Block, ch: Channel) -> Block:
    """``block`` as the path runs it: an M1 whose switch is off does not stop."""
    if block.stop == StopKind.OPTIONAL and not ch.switches.m01_stop_enable:
        return replace(block, stop=StopKind.NONE)
    return block


def skip_mask_refused(value: int) -> Refusal | None:
    """Why ``value`` is no skip level mask (bits beyond level 10), or None."""
    if value & ~SKIP_LEVELS_MASK:
        return Refusal(RefusalReason.INVALID_VALUE,
                       f"skip level mask 0x{value:x} has bits beyond level 10 "
                       f"(0x{SKIP_LEVELS_MASK:x})")
    return None


