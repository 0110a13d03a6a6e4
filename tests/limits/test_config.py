"""The ``[limits]`` table: defaults, what is refused, and how a limit reaches the service."""

from __future__ import annotations

import msgpack
import pytest

from cnc_objects.protocol.constants import MAX_DATA_BYTES, PROGRAM_STORE_MAX_BYTES
from cnc_objects.service.config import ConfigError, build_config
from cnc_objects.service.limits import LimitsConfig, oversized_reply, request_head


def test_every_limit_has_a_default_and_a_description() -> None:
    limits = build_config().limits
    assert limits == LimitsConfig()
    assert limits.max_frame_bytes == MAX_DATA_BYTES + 4096
    assert limits.frame_hard_cap_bytes == 2 * limits.max_frame_bytes
    assert (limits.notifications_per_client, limits.notifications_total) == (1000, 20_000)
    assert limits.program_max_bytes == PROGRAM_STORE_MAX_BYTES >= 200_000_000
    for name, field in LimitsConfig.model_fields.items():
        assert field.description, f"[limits] {name} has no description"


def test_a_limit_is_set_in_the_configuration() -> None:
    limits = build_config({"limits": {"notifications_per_client": 5, "send_hwm_messages": 50}})
    assert limits.limits.notifications_per_client == 5
    assert limits.limits.send_hwm_messages == 50
    assert limits.limits.notifications_total == 20_000  # the others keep their defaults


@pytest.mark.parametrize(("limits", "words"), [
    ({"max_frame_bytes": 100}, "limits.max_frame_bytes"),
    ({"notifications_total": 0}, "limits.notifications_total"),
    ({"requests_per_s_per_client": -1}, "limits.requests_per_s_per_client"),
    ({"handles_per_client": 10}, "limits.handles_per_client"),  # handles cost nothing
    ({"program_max_bytes": 2 << 40}, "limits.program_max_bytes"),
    ({"store_max_total_bytes": 0}, "limits.store_max_total_bytes"),
])
def test_a_bad_limit_is_refused_naming_the_key(limits: dict, words: str) -> None:
    with pytest.raises(ConfigError) as caught:
        build_config({"limits": limits})
    assert words in str(caught.value)


def test_a_small_frame_limit_with_a_small_program_limit_is_accepted() -> None:
    limits = build_config({"limits": {"max_frame_bytes": 65536, "program_max_bytes": 60_000}})
    assert limits.limits.frame_hard_cap_bytes == 131072


def test_the_head_of_a_frame_names_invoke_id_and_command_without_unpacking_it() -> None:
    frame = msgpack.packb([7, 3, 553, 0x120101, 9, b"x" * 100_000], use_bin_type=True)
    assert request_head(frame) == (7, 3)
    reply = msgpack.unpackb(oversized_reply(frame, 4096))
    assert reply[:3] == [7, 3, 0x70B] and "max_frame_bytes" in reply[3]


@pytest.mark.parametrize("frame", [
    b"", b"\x00" * 64, msgpack.packb([0, 2, 553]), msgpack.packb([7]),
    msgpack.packb(["7", 2, 553]), msgpack.packb({"a": 1}), msgpack.packb([2**32, 2]),
    msgpack.packb([7, "read"]), b"\xdd\xff\xff\xff\xff",
])
def test_a_head_without_an_invoke_id_gets_no_reply(frame: bytes) -> None:
    assert request_head(frame) is None
    assert oversized_reply(frame, 4) is None
