"""``cnc_alarms``: what a test needs to assert "this program raised exactly these alarms".

    def test_a_bad_block(cnc_client, cnc_alarms):
        cnc_client.upload("bad.nc", b"G1 X10\\nM30\\n")
        with pytest.raises(ChannelError):
            run_program(cnc_client, "bad.nc")
        assert cnc_alarms.raised_ids() == [20008]

The recorder counts from the moment it was made (or last ``clear``ed): alarms raised
before are not its business, so a test on a shared service sees only its own. It reads
the service's alarm objects through the test's client (docs/alarms.md).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from cnc_objects.protocol.alarm_values import AlarmState

if TYPE_CHECKING:
    from cnc_objects.clients import AlarmInfo, Client

WAIT_TIMEOUT_S = 30.0  # wall time; a loaded CI machine is slow


def _other_than(value: Any) -> Callable[[Any], bool]:
    """A value that is not ``value`` (``wait_for``'s predicate)."""
    return lambda changed: changed != value


class AlarmRecorder:
    """The alarms raised since the recorder started (``cnc_alarms`` fixture)."""

    def __init__(self, client: Client) -> None:
        self.client = client
        self.since = int(client.read("alarm_raised_r"))  # the last sequence number before

    def raised(self) -> list[AlarmInfo]:
        """The alarms raised since the start (or ``clear``), oldest first, in their state
        now. The history must hold them ([limits] alarm_history_max)."""
        listed = self.client.alarms(history=True)
        found = {a.sequence: a for a in (*listed.history, *listed.active)
                 if a.sequence > self.since}
        return [found[s] for s in sorted(found)]

    def raised_ids(self) -> list[int]:
        """The ids of ``raised()``, oldest first: ``== [20008]`` asserts exactly one."""
        return [a.id for a in self.raised()]

    def active_ids(self) -> list[int]:
        """Ids of the alarms raised since the start that are still active."""
        return [a.id for a in self.raised() if a.state != AlarmState.CLEARED]

    def wait_for(self, alarm_id: int, timeout_s: float = WAIT_TIMEOUT_S) -> AlarmInfo:
        """Wait until an alarm with ``alarm_id`` was raised (since the start); return it.
        ``AssertionError`` naming what was raised when it does not come in time."""
        from .helpers import wait_for

        deadline = time.monotonic() + timeout_s
        while True:
            changes = self.client.read("alarm_changes_r")
            for alarm in self.raised():
                if alarm.id == alarm_id:
                    return alarm
            left_s = deadline - time.monotonic()
            if left_s <= 0:
                raise AssertionError(f"alarm {alarm_id} was not raised within {timeout_s:g} s;"
                                     f" raised: {self.raised_ids() or 'none'}")
            try:  # the next change of the alarms, not a sleep
                wait_for(self.client, "alarm_changes_r", _other_than(changes), left_s)
            except TimeoutError:
                continue  # the deadline check above names what was raised

    def clear(self) -> None:
        """Acknowledge every active alarm and count from here on."""
        self.client.acknowledge_all_alarms()
        self.since = int(self.client.read("alarm_raised_r"))
