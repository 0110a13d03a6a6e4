"""The decoder's work counter (``nc.work_guard``): a RESET is seen within
``LOOK_EVERY_STEPS`` steps whatever the program does, and the endless-program guard
counts steps without a block, loops or not."""

from __future__ import annotations

from itertools import islice

import pytest

from cnc_objects.service.kernel.nc import Decoder, NcError, NcErrorId, work_guard
from cnc_objects.service.kernel.nc.errors import DecodingCancelled
from cnc_objects.service.kernel.nc.technology import Surroundings
from tests.support.endless_programs import many_labels, nested_calls

from .support import AXES, TOOLS, decoder, error_of, loader_of

CANCEL_AFTER_LOOKS = 3  # the run is cancelled at the decoder's third look
#: programs that never yield a block (the first two once never looked for a RESET)
ENDLESS = {
    "nested calls": (nested_calls(), True),
    "labels and a backward $GOTO": (many_labels(5000), False),
    "$WHILE with a #MSG": ('$WHILE 1\n#MSG ["x"]\n$ENDWHILE\nM30\n', False),
    "a $GOTO back over a call": ("N1:\nLL A\n$GOTO N1\nM30\n%L A\nM17\n", False),
    # the hot path passes over these lines: it counts them as steps too
    "modal-only lines and a $GOTO": ("N1: G1\n" + "F500\n" * 3000 + "$GOTO N1\nM30\n", False),
}


@pytest.mark.parametrize("name", sorted(ENDLESS))
def test_a_reset_is_seen_within_bounded_work(name: str) -> None:
    text, manual = ENDLESS[name]
    d = decoder(text, manual=manual)
    looks = 0

    def cancelled() -> bool:
        nonlocal looks
        looks += 1
        return looks >= CANCEL_AFTER_LOOKS

    d.cancelled = cancelled
    with pytest.raises(DecodingCancelled):
        list(d.blocks())
    assert looks == CANCEL_AFTER_LOOKS


@pytest.mark.parametrize("name", sorted(ENDLESS))
def test_the_guard_counts_steps_not_loops(monkeypatch, name: str) -> None:
    monkeypatch.setattr(work_guard, "IDLE_STEPS_MAX", 5000)
    text, manual = ENDLESS[name]
    e = error_of(text, manual=manual)
    assert e.id == NcErrorId.ENDLESS_LOOP and e.line >= 1 and e.column >= 1
    assert "5000 steps" in e.message


def test_the_limit_comes_from_the_surroundings() -> None:
    d = Decoder("$WHILE 1\n$ENDWHILE\nM30\n", "p.nc", axes=AXES, loader=loader_of(None),
                tools=TOOLS, surroundings=Surroundings(idle_steps_max=1000))
    with pytest.raises(NcError) as info:
        list(d.blocks())
    assert info.value.id == NcErrorId.ENDLESS_LOOP and "1000 steps" in info.value.message


def test_blocks_reset_the_count(monkeypatch) -> None:
    """A loop that moves is no endless program: it runs as long as blocks are taken."""
    monkeypatch.setattr(work_guard, "IDLE_STEPS_MAX", 1000)
    text = ("#VAR\nV.L.I = 0\n#ENDVAR\nG1 F100\n$WHILE 1\n"
            + "V.L.I = V.L.I + 1\n" * 50 + "G1 X[V.L.I MOD 7]\n$ENDWHILE\nM30\n")
    assert len(list(islice(decoder(text).blocks(), 200))) == 200
