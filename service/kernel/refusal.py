"""Why the kernel did not apply a command: a reason code and a sentence for the user.

A command answers None (done) or a ``Refusal``; the binding maps the reasons to ADS
return codes. Its own module so that both the commands and the channel runners' face in
``state`` (``ChannelRunnerView``) name it without importing each other.
"""

from __future__ import annotations

from enum import IntEnum
from typing import NamedTuple


class RefusalReason(IntEnum):
    """Why the kernel did not apply a command."""

    INVALID_VALUE = 1  # the value is outside what the object accepts
    NOT_READY = 2  # the kernel or channel is not in a state that allows it
    BUSY = 3  # try again in a later cycle
    NOT_FOUND = 4  # the named thing (a program) does not exist
    NOT_SUPPORTED = 5  # the function is not configured (e.g. not in P-CHAN-00650)


class Refusal(NamedTuple):
    """A command the kernel did not apply, with a sentence for the user."""

    reason: RefusalReason
    message: str
