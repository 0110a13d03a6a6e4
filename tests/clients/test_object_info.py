"""Browse rows into ``ObjectInfo``: value names, rows of older and later services."""

from __future__ import annotations

import pytest

from cnc_objects.clients import AdsError, ObjectInfo
from cnc_objects.clients.object_info import Scale

ROW = ["ch1.mc_active_state_r", 553, 0x120101, 0x3002, "UNS32", 4, "r", "-", "State"]


def test_value_names_become_a_dict_by_value() -> None:
    info = ObjectInfo.from_row([*ROW, [[1, "DESELECTED"], [3, "READY"]]])
    assert info.enum == {1: "DESELECTED", 3: "READY"}
    assert (info.name, info.group, info.offset, info.type) == (ROW[0], 0x120101, 0x3002, "UNS32")


def test_a_row_of_a_service_without_value_names_has_an_empty_enum() -> None:
    assert ObjectInfo.from_row(ROW).enum == {}
    assert ObjectInfo(*ROW).enum == {}  # built by hand (tests, benches): the default


def test_fields_a_later_service_adds_are_ignored() -> None:
    info = ObjectInfo.from_row([*ROW, [[3, "READY"]], [], "something new", 7])
    assert info.enum == {3: "READY"} and info.description == "State" and info.scale is None


POSITION = ["ch1.ax1.command_position_acs", 553, 0x120101, 0x10005, "SGN32", 4, "r", "0.1 um",
            "Command position"]


def test_the_scale_says_how_people_read_the_value() -> None:
    info = ObjectInfo.from_row([*POSITION, [], ["mm", 0.0001, 4]])
    assert info.scale == Scale("mm", 0.0001, 4)
    assert ObjectInfo.from_row([*POSITION, []]).scale is None  # a service without scales


@pytest.mark.parametrize("scale", [["mm"], ["mm", 0, 4], ["mm", -1.0, 4], [5, 1.0, 2],
                                   ["mm", 1e-4, 99], "mm"])
def test_malformed_scales_raise_the_library_error(scale: object) -> None:
    with pytest.raises(AdsError) as caught:
        ObjectInfo.from_row([*POSITION, [], scale])
    assert caught.value.code == 0x754 and "browse row" in str(caught.value)


def test_object_infos_stay_hashable() -> None:
    info = ObjectInfo.from_row([*ROW, [[3, "READY"]]])
    assert {info: 1}[ObjectInfo.from_row([*ROW, [[3, "READY"]]])] == 1


@pytest.mark.parametrize("row", [ROW[:8], [*ROW, [[3]]], [*ROW, [["x", "READY"]]], [*ROW, 5], 7])
def test_malformed_rows_raise_the_library_error(row: object) -> None:
    with pytest.raises(AdsError) as caught:
        ObjectInfo.from_row(row)
    assert caught.value.code == 0x754 and "browse row" in str(caught.value)
