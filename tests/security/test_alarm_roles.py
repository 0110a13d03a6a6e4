"""Alarms and roles (ZeroMQ with CURVE): a monitor reads the alarms but may not
acknowledge them (ADS 0x704 naming the role); an operator may (docs/alarms.md)."""

from __future__ import annotations

import pytest

from cnc_objects.clients import AdsError, ChannelError, Client
from cnc_objects.protocol.alarm_values import AlarmState
from cnc_objects.testing import ServiceProcess

INVALIDACCESS = 0x704


def client(service: ServiceProcess, role: str) -> Client:
    assert service.keys is not None
    return Client(service.endpoint, key_file=service.keys.client(role), timeout_s=10)


def test_a_monitor_lists_alarms_and_only_an_operator_acknowledges(
        keyed: ServiceProcess) -> None:
    with client(keyed, "admin") as admin:
        admin.upload("alarm-roles.nc", b"G0 X1\nG1 X10\nM30\n")
    with client(keyed, "operator") as operator, client(keyed, "monitor") as monitor:
        operator.reset(1)
        operator.run_program("alarm-roles.nc", 1)
        with pytest.raises(ChannelError):
            operator.wait_program(1, 30)
        [alarm] = [a for a in monitor.alarms().active if a.id == 20008]
        for acknowledge in (lambda: monitor.acknowledge_alarm(alarm.sequence),
                            monitor.acknowledge_all_alarms):
            with pytest.raises(AdsError) as refused:
                acknowledge()
            assert refused.value.code == INVALIDACCESS
            assert "role monitor may not write alarm_acknowledge" in str(refused.value)
        assert [a.state for a in monitor.alarms().active if a.sequence == alarm.sequence] == [
            AlarmState.ACTIVE]
        operator.acknowledge_alarm(alarm.sequence)
        assert [a.state for a in monitor.alarms().active if a.sequence == alarm.sequence] == [
            AlarmState.ACKNOWLEDGED]
        operator.reset(1)
