"""The bridge's pure parts: payloads, topics, configuration, backoff, outbox."""

from __future__ import annotations

import json
from datetime import UTC, datetime, timedelta, timezone

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cnc_objects.clients import ObjectInfo, Sample
from cnc_objects.clients.mqtt import payloads
from cnc_objects.clients.mqtt.config import DEFAULT_OBJECTS, BridgeConfig, expand_patterns, parse_broker
from cnc_objects.clients.mqtt.outbox import OFFLINE, ONLINE, Outbox
from cnc_objects.clients.mqtt.payloads import RequestError, SetRequest
from cnc_objects.clients.mqtt.retry import Backoff
from cnc_objects.clients.mqtt.topics import Topics
from cnc_objects.clients.object_info import Scale
from cnc_objects.protocol.datatypes import parse_type

TS = datetime(2026, 11, 21, 10, 0, 0, 123456, tzinfo=UTC)


# ------------------------------------------------------------------ value messages


def test_value_message_fields() -> None:
    message = json.loads(payloads.encode_value(750, "0.1 %", TS, 17))
    assert message == {"value": 750, "unit": "0.1 %", "ts": "2026-11-21T10:00:00.123456Z", "seq": 17}


@pytest.mark.parametrize(
    ("value", "unit", "expected_value", "expected_unit"),
    [
        (True, "-", True, None),
        ("part.nc", "-", "part.nc", None),
        ("Größe", "", "Größe", None),
        (1.5, "mm/s", 1.5, "mm/s"),
        (float("nan"), "mm", None, "mm"),  # JSON has no NaN
        (float("inf"), "mm", None, "mm"),
    ],
)
def test_value_types_and_units(value, unit, expected_value, expected_unit) -> None:
    message = json.loads(payloads.encode_value(value, unit, TS, 1))
    assert message["value"] == expected_value and message.get("unit") == expected_unit
    # A unitless object's message has no "unit" key at all (not null).
    assert ("unit" in message) == (expected_unit is not None)
    assert "name" not in message  # not an enumeration


STATES = {1: "DESELECTED", 2: "SELECTED", 3: "READY", 4: "ACTIVE", 5: "HOLD", 6: "ERROR"}


def test_enumeration_values_carry_their_name() -> None:
    raw = payloads.encode_value(3, "-", TS, 2, STATES)
    # The exact payload of docs/mqtt.md, key order included.
    assert raw == b'{"value": 3, "name": "READY", "ts": "2026-11-21T10:00:00.123456Z", "seq": 2}'


def test_enumeration_value_without_a_name_has_a_null_name() -> None:
    message = json.loads(payloads.encode_value(9, "-", TS, 1, STATES))
    assert message == {"value": 9, "name": None, "ts": "2026-11-21T10:00:00.123456Z", "seq": 1}


def test_enumeration_with_a_unit_keeps_both() -> None:
    message = json.loads(payloads.encode_value(0, "mode", TS, 1, {0: "OFF"}))
    assert (message["name"], message["unit"]) == ("OFF", "mode")


PERCENT = Scale("%", 0.1, 1)  # what the service gives for an override in 0.1 %


def test_a_scaled_value_goes_out_in_engineering_units_with_the_raw_beside() -> None:
    raw = payloads.encode_value(755, "0.1 %", TS, 3, scale=PERCENT)
    # The exact payload of docs/mqtt.md, key order included.
    assert raw == (b'{"value": 75.5, "unit": "%", "raw": 755, "raw_unit": "0.1 %", '
                   b'"ts": "2026-11-21T10:00:00.123456Z", "seq": 3}')
    position = json.loads(payloads.encode_value(1890, "0.1 um", TS, 1,
                                                scale=Scale("mm", 1e-4, 4)))
    assert (position["value"], position["unit"], position["raw"]) == (0.189, "mm", 1890)


def test_values_have_no_float_noise() -> None:
    """Rounded to the object's resolution: 0.18900000000007822 s is 0.189 s."""
    message = json.loads(payloads.encode_value(0.18900000000007822, "s", TS, 1,
                                               scale=Scale("s", 1.0, 6)))
    assert message == {"value": 0.189, "unit": "s", "ts": "2026-11-21T10:00:00.123456Z",
                       "seq": 1}  # its own unit: only rounded, no "raw"
    speed = json.loads(payloads.encode_value(3150.0000000000005, "um/s", TS, 1,
                                             scale=Scale("mm/min", 0.06, 3)))
    assert (speed["value"], speed["raw"]) == (189.0, 3150.0)


def test_a_request_gives_engineering_units_or_the_raw_value() -> None:
    assert payloads.decode_set(b'{"raw": 750, "id": "r"}') == SetRequest(750, "r", raw=True)
    info = ObjectInfo("ch1.mc_command_feed_override_w", 553, 0x120101, 9, "UNS16", 2, "w",
                      "0.1 %", "", scale=PERCENT)
    assert payloads.from_engineering(info, 75) == 750
    assert payloads.from_engineering(info, 75.5) == 755
    assert payloads.from_engineering(info, "fast") == "fast"  # coerce refuses it, by type


def test_timestamp_is_utc_whatever_the_zone() -> None:
    cet = TS.astimezone(timezone(timedelta(hours=1)))
    assert payloads.iso_utc(cet) == "2026-11-21T10:00:00.123456Z"


# ------------------------------------------------------------------ requests


def test_decode_set_request() -> None:
    assert payloads.decode_set(b'{"value": 5, "id": "a-1"}') == SetRequest(5, "a-1")
    assert payloads.decode_set(b'{"value": "x", "extra": 1}') == SetRequest("x", None)


@pytest.mark.parametrize(
    ("payload", "code", "request_id", "says"),
    [
        (b"", 0x70B, None, "not JSON"),
        (b"\xff\xfe", 0x70B, None, "not JSON"),
        (b"{bad", 0x70B, None, "not JSON"),
        (b"[1, 2]", 0x70B, None, "JSON object"),
        (b"42", 0x70B, None, "JSON object"),
        (b'{"id": "x"}', 0x70B, "x", 'needs "value"'),
        (b'{"value": 75, "raw": 750, "id": "x"}', 0x70B, "x", "one of them"),
        (b'{"value": 1, "id": 5}', 0x70B, None, '"id" must be a string'),
        (b'{"value": 1, "id": ""}', 0x70B, None, "empty"),
        (b'{"value": 1, "id": "a/b"}', 0x70B, None, "'/'"),
        (b'{"value": 1, "id": "a+#"}', 0x70B, None, "'#'"),
        (b'{"value": 1, "id": "' + b"x" * 129 + b'"}', 0x70B, None, "1..128"),
    ],
)
def test_malformed_requests(payload: bytes, code: int, request_id: str | None, says: str) -> None:
    with pytest.raises(RequestError) as caught:
        payloads.decode_set(payload)
    assert caught.value.code == code and caught.value.request_id == request_id
    assert says in str(caught.value) and str(caught.value).startswith(f"ADS 0x{code:x} ")


@pytest.mark.parametrize(
    ("type_name", "value", "expected"),
    [
        ("BOOLEAN", True, True),
        ("BOOLEAN", 0, False),
        ("UNS16", 750, 750),
        ("UNS16", 750.0, 750),
        ("SGN32", -5, -5),
        ("REAL64", 2, 2.0),
        ("REAL64", 0.25, 0.25),
        ("STRING(84)", "part.nc", "part.nc"),
    ],
)
def test_coerce_by_type(type_name: str, value, expected) -> None:
    converted = payloads.coerce(parse_type(type_name), value, "obj")
    assert converted == expected and type(converted) is type(expected)


@pytest.mark.parametrize(
    ("type_name", "value", "says"),
    [
        ("BOOLEAN", 2, "true/false"),
        ("BOOLEAN", "true", "true/false"),
        ("UNS16", 7.5, "an integer"),
        ("UNS16", True, "an integer"),
        ("UNS16", "750", "an integer"),
        ("UNS16", 70000, "outside"),
        ("UNS16", -1, "outside"),
        ("REAL64", "1.5", "a number"),
        ("REAL64", None, "a number"),
        ("STRING(8)", 5, "a string"),
        ("STRING(8)", "much too long", "STRING(8)"),
    ],
)
def test_coerce_refuses(type_name: str, value, says: str) -> None:
    with pytest.raises(RequestError) as caught:
        payloads.coerce(parse_type(type_name), value, "obj")
    assert caught.value.code == 0x706 and says in str(caught.value)


def test_long_values_are_cut_in_messages() -> None:
    with pytest.raises(RequestError) as caught:
        payloads.coerce(parse_type("UNS16"), "x" * 1000, "obj")
    assert len(str(caught.value)) < 150


@given(st.integers(-(2**31), 2**31 - 1))
def test_integers_round_trip_through_json(number: int) -> None:
    request = payloads.decode_set(json.dumps({"value": number}).encode())
    assert payloads.coerce(parse_type("SGN32"), request.value, "obj") == number


def test_replies() -> None:
    assert json.loads(payloads.encode_ok()) == {"ok": True}
    assert json.loads(payloads.encode_ok("cnc/m/set/x")) == {"ok": True, "topic": "cnc/m/set/x"}
    assert json.loads(payloads.encode_error(0x704, "ADS 0x704 INVALIDACCESS: no")) == {
        "ok": False, "code": "0x704", "error": "ADS 0x704 INVALIDACCESS: no"}


# ------------------------------------------------------------------ topics, config


def test_topics() -> None:
    topics = Topics("mill1")
    assert topics.status == "cnc/mill1/status"
    assert (topics.value("gpCh[0].bahn_state.dist_prog_start")
            == "cnc/mill1/gpCh[0].bahn_state.dist_prog_start")
    assert topics.set_filter == "cnc/mill1/set/#"
    assert topics.object_of_set("cnc/mill1/set/ch1.x") == "ch1.x"
    assert topics.object_of_set("cnc/mill1/ch1.x") is None
    assert topics.reply("r1") == "cnc/mill1/reply/r1" and topics.no_id_reply == "cnc/mill1/reply"
    for bad in ("", "a/b", "a+", "#"):
        with pytest.raises(ValueError):
            Topics(bad)


@pytest.mark.parametrize(
    ("text", "tls", "expected"),
    [
        ("broker", False, ("broker", 1883)),
        ("broker", True, ("broker", 8883)),
        ("10.0.0.1:1884", False, ("10.0.0.1", 1884)),
        ("[::1]", False, ("::1", 1883)),
        ("[::1]:1884", True, ("::1", 1884)),
    ],
)
def test_parse_broker(text: str, tls: bool, expected: tuple[str, int]) -> None:
    assert parse_broker(text, tls) == expected


@pytest.mark.parametrize("text", ["", ":1", "h:", "h:0", "h:65536", "h:x", "::1", "[::1", "[::1]x", "a b"])
def test_parse_broker_refuses(text: str) -> None:
    with pytest.raises(ValueError):
        parse_broker(text)


def test_default_objects_and_expansion() -> None:
    assert expand_patterns(["@default", "ch1.x", "ch*.mc_active_mode_r"]) == (*DEFAULT_OBJECTS, "ch1.x")
    config = BridgeConfig("tcp://h:1", "b", "m", objects=("@default",))
    assert config.objects == DEFAULT_OBJECTS and config.mqtt_client_id == "cnc-mqtt-m"
    with pytest.raises(ValueError):
        BridgeConfig("tcp://h:1", "b", "m", reconnect_initial_s=2, reconnect_max_s=1)


# ------------------------------------------------------------------ backoff, outbox


def test_backoff_doubles_to_the_cap_and_resets() -> None:
    backoff = Backoff(0.1, 1.0)
    assert [backoff.next_delay_s() for _ in range(6)] == [0.1, 0.2, 0.4, 0.8, 1.0, 1.0]
    backoff.reset()
    assert backoff.next_delay_s() == 0.1
    with pytest.raises(ValueError):
        Backoff(0, 1)


def _info(name: str) -> ObjectInfo:
    return ObjectInfo(name, 553, 0x120101, 1, "UNS16", 2, "r", "-", "")


def test_outbox_keeps_the_newest_sample_and_the_order_of_changes() -> None:
    outbox = Outbox()
    a, b = _info("a"), _info("b")
    outbox.put(a, Sample("a", 1, TS, 1))
    outbox.put(b, Sample("b", 5, TS, 1))
    outbox.put(a, Sample("a", 2, TS, 2))  # replaces a's unsent 1
    outbox.set_status(ONLINE)
    pending, status = outbox.take()
    assert [(p.info.name, p.sample.value) for p in pending] == [("a", 2), ("b", 5)]
    assert status == ONLINE
    assert outbox.take() == ([], None)
    outbox.resend_all()  # a new broker connection
    pending, status = outbox.take()
    assert [p.sample.value for p in pending] == [2, 5] and status == ONLINE
    outbox.set_status(OFFLINE)
    assert outbox.take() == ([], OFFLINE)
