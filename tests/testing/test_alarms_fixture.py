"""The plugin's ``cnc_alarms`` fixture: "this program raised exactly these alarms", each
test on a service of its own (virtual clock)."""

from __future__ import annotations

import pytest

from cnc_objects.clients import ChannelError, Client
from cnc_objects.testing import run_program
from cnc_objects.testing.alarms import AlarmRecorder

SYNCHK, MACHINE_LOCK = 0x8, 0x40


def test_a_program_raises_exactly_its_alarm(cnc_client: Client,
                                            cnc_alarms: AlarmRecorder) -> None:
    assert cnc_alarms.raised_ids() == []
    cnc_client.upload("bad.nc", b"G0 X1\nG1 X10\nM30\n")
    with pytest.raises(ChannelError):
        run_program(cnc_client, "bad.nc")
    assert cnc_alarms.raised_ids() == [20008]
    assert cnc_alarms.active_ids() == [20008]
    cnc_client.reset()
    assert cnc_alarms.active_ids() == []  # RESET cleared it
    assert cnc_alarms.raised_ids() == [20008]  # raised it was


def test_wait_for_and_clear(cnc_client: Client, cnc_alarms: AlarmRecorder) -> None:
    cnc_client.write("ch1.mc_command_execution_mode_w", SYNCHK | MACHINE_LOCK)
    cnc_client.upload("check.nc", b"G1 X10 F100\nG999\nG1 X[1/0]\nM30\n")
    cnc_client.run_program("check.nc")  # returns at once; the check runs on
    alarm = cnc_alarms.wait_for(20201)
    assert (alarm.line, alarm.column) == (3, 7)
    assert cnc_alarms.raised_ids()[:2] == [20120, 20201]
    cnc_client.wait_program(1, 30)
    cnc_alarms.clear()
    assert cnc_alarms.raised_ids() == [] and cnc_client.alarms().active == ()


def test_wait_for_names_what_was_raised_when_its_alarm_does_not_come(
        cnc_client: Client, cnc_alarms: AlarmRecorder) -> None:
    cnc_client.upload("bad.nc", b"G1 X10\nM30\n")
    with pytest.raises(ChannelError):
        run_program(cnc_client, "bad.nc")
    with pytest.raises(AssertionError, match=r"alarm 50101 was not raised within 0.5 s; "
                                             r"raised: \[20008\]"):
        cnc_alarms.wait_for(50101, timeout_s=0.5)
