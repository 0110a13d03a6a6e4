"""``Channel.frozen()`` copies every field into the same field (by keyword: with the
channel made of a few parts, a keyword call is cheap); this test gives every field a
value of its own and finds a field the copy forgets or puts in another's place."""

from __future__ import annotations

from dataclasses import fields

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.kernel_state import KernelState
from cnc_objects.service.kernel.state import Channel


def test_frozen_copies_every_field_into_the_field_of_its_name() -> None:
    channel = KernelState.from_config(build_config()).channels[0]
    marks = {f.name: object() for f in fields(Channel) if f.name != "axes"}
    for name, mark in marks.items():
        setattr(channel, name, mark)
    copy = channel.frozen()
    shifted = [name for name, mark in marks.items() if getattr(copy, name) is not mark]
    assert shifted == []
    assert [a.name for a in copy.axes] == [a.name for a in channel.axes]
    assert all(c is not a for c, a in zip(copy.axes, channel.axes, strict=True))  # copies
