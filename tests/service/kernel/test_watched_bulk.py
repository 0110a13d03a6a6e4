"""A watched cruise under the event-speed clock (issue 37): the cycles an observer must
see are published by the bulk that runs through them, not stepped one by one.

Before, the bulk stopped one cycle short of each due cycle and the due cycle ran as a
whole cycle (the channel's decoder hand-over, planning, technology and wait reason): with
20 subscriptions of 10 ms the kernel did one whole cycle in ten. A due cycle that only
cruises is no event; the bulk runs through it and publishes it, and what it shows is
what stepping shows at that cycle, bit for bit (the property test in
test_event_speed_clock.py holds it for generated programs and periods).
"""

from __future__ import annotations

import pytest

from cnc_objects.service.kernel.channel_run import ChannelRunner
from tests.support.event_speed import assert_same, run

#: long blocks at F600: 30 s of cruising, a handful of block ends
LONG_BLOCKS = "G90 G1 F600\n" + "".join(
    f"X{(k % 2) * 5} Y{k * 0.5:g}\n" for k in range(6)) + "M30\n"
PERIOD = 10  # cycles: a 10 ms subscription on the 1 ms cycle


def test_due_cycles_of_a_cruise_are_published_without_a_whole_cycle(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Observed every 10 cycles, the event clock publishes every due cycle with the
    stepping run's values, and runs the channel's whole cycle only at events (block
    ends, start, end): far fewer than one in ten cycles."""
    whole = [0]
    cycle = ChannelRunner.cycle

    def counted(self: ChannelRunner, time_s: float) -> bool:
        if self.channel.channel_id == 1:
            whole[0] += 1
        return cycle(self, time_s)

    monkeypatch.setattr(ChannelRunner, "cycle", counted)
    recording = run(LONG_BLOCKS, True, (PERIOD,), {})
    run_whole, whole[0] = whole[0], 0
    due = set(range(PERIOD, recording.end_cycle + 1, PERIOD))
    assert due <= recording.values.keys()
    assert run_whole < recording.end_cycle / 100, (run_whole, recording.end_cycle)
    monkeypatch.setattr(ChannelRunner, "cycle", cycle)
    assert_same(LONG_BLOCKS, (PERIOD,), {})  # and every value equals stepping's
