"""The DataValues the front end makes (``service.opcua.values``): handed to asyncua's
monitored items as they are, without asyncua's deep copy, and on the wire the same as
asyncua's own DataValues."""

from __future__ import annotations

from asyncua import ua
from asyncua.server.monitored_item_service import MonitoredItemValues
from asyncua.ua.ua_binary import struct_to_binary

from cnc_objects.service.opcua.values import bad, good


def test_a_sample_reaches_the_monitored_item_without_a_copy() -> None:
    values = MonitoredItemValues()
    sample = good(12.5, ua.VariantType.Double)
    values.set_current_datavalue(sample)
    assert values.get_current_datavalue() is sample
    refused = bad(ua.StatusCodes.BadInternalError)
    values.set_current_datavalue(refused)
    assert values.get_current_datavalue() is refused
    assert values.get_old_datavalue() is sample


def test_asyncuas_own_values_are_still_copied() -> None:
    values = MonitoredItemValues()
    plain = ua.DataValue(ua.Variant(1.0, ua.VariantType.Double))
    values.set_current_datavalue(plain)
    assert values.get_current_datavalue() is not plain
    assert values.get_current_datavalue() == plain


def test_a_sample_encodes_and_compares_as_a_plain_data_value() -> None:
    sample = good([1, 2, 3], ua.VariantType.Int32)
    plain = ua.DataValue(sample.Value, SourceTimestamp=sample.SourceTimestamp,
                         ServerTimestamp=sample.ServerTimestamp)
    assert sample == plain and plain == sample
    assert struct_to_binary(ua.MonitoredItemNotification(ClientHandle=7, Value=sample)) == \
        struct_to_binary(ua.MonitoredItemNotification(ClientHandle=7, Value=plain))
    assert sample != good([1, 2, 4], ua.VariantType.Int32)
