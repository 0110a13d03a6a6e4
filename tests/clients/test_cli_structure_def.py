"""``cnc ads structure-def NAME`` (issue 41, item 6): the structure_def it prints, used as
printed with pyads' ``read_structure_by_name`` / ``write_structure_by_name`` against the
real service, reads and writes the right values; docs/ads.md shows its output as it is.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyads
import pytest

from cnc_objects.testing import ServiceProcess
from tests.support.cli import cnc
from tests.support.pyads_plc import pyads_service

LOCAL_NET_ID = "127.0.0.1.1.42"  # this test process, as pyads' AMS router
DOCS = Path(__file__).resolve().parents[2] / "docs" / "ads.md"


@dataclass
class Plc:
    service: ServiceProcess
    plc: pyads.Connection


@pytest.fixture(scope="module")
def ads(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Plc]:
    with pyads_service(tmp_path_factory.mktemp("structure-def"), LOCAL_NET_ID) as (service, (plc,)):
        yield Plc(service, plc)


def printed(ads: Plc, name: str) -> tuple[str, dict[str, Any]]:
    """What ``cnc ads structure-def NAME`` prints, and the names it defines when run."""
    result = cnc("ads", "structure-def", name, endpoint=ads.service.endpoint)
    assert result.returncode == 0, result.stderr
    defined: dict[str, Any] = {"pyads": pyads}
    exec(result.stdout, defined)  # the point: it is Python to copy
    return result.stdout, defined


def test_the_spindle_reads_and_writes_with_the_printed_structure_def(ads: Plc) -> None:
    text, defined = printed(ads, "gpCh[0].spindle")
    spindle_def = defined["ST_gpCh_spindle"]
    assert ("_pad_0x0011", pyads.PLCTYPE_BYTE, 7) in spindle_def
    assert pyads.size_of_structure(spindle_def) == 32
    values = ads.plc.read_structure_by_name("gpCh[0].spindle", spindle_def)
    for member in ("mode_r", "override_w", "cmd_rev_r", "position_r"):
        assert values[member] == ads.plc.read_by_name(f"gpCh[0].spindle.{member}"), member
    before = values["override_w"]
    values["override_w"] = 500
    try:
        ads.plc.write_structure_by_name("gpCh[0].spindle", values, spindle_def)
        assert ads.plc.read_by_name("gpCh[0].spindle.override_w", pyads.PLCTYPE_UINT) == 500
    finally:
        ads.plc.write_by_name("gpCh[0].spindle.override_w", before, pyads.PLCTYPE_UINT)


def test_nested_structs_and_arrays_of_structs(ads: Plc) -> None:
    """``bahn_state`` holds an array of structs that hold a struct; the channel's
    technology units are an array of structs (pyads' ``array_size``)."""
    _, defined = printed(ads, "gpCh[0].bahn_state")
    state = ads.plc.read_structure_by_name("gpCh[0].bahn_state", defined["ST_gpCh_bahn_state"])
    assert state["dist_prog_start"] == ads.plc.read_by_name("gpCh[0].bahn_state.dist_prog_start")
    axes = state["coord_r"]
    assert len(axes) == 3 and [a["hb_display_r"]["operation_mode"] for a in axes] == [
        ads.plc.read_by_name(f"gpCh[0].bahn_state.coord_r[{k}].hb_display_r.operation_mode")
        for k in range(3)]
    text, defined = printed(ads, "gpCh[0].techno_unit_std_sync")
    assert "array_size=16" in text
    units = ads.plc.read_structure_by_name("gpCh[0].techno_unit_std_sync",
                                           defined["ST_gpCh_techno_unit_std_sync"], array_size=16)
    assert len(units) == 16 and units[3]["attribut_r"]["nr"] == ads.plc.read_by_name(
        "gpCh[0].techno_unit_std_sync[3].attribut_r.nr")


def test_the_whole_channel_struct_has_the_size_of_its_symbol(ads: Plc) -> None:
    _, defined = printed(ads, "gpCh[1]")
    assert pyads.size_of_structure(defined["HLI_CHANNEL"]) == 0x1000
    channel = ads.plc.read_structure_by_name("gpCh[1]", defined["HLI_CHANNEL"])
    assert channel["spindle"]["override_w"] == ads.plc.read_by_name("gpCh[1].spindle.override_w")


@pytest.mark.parametrize(("name", "code", "says"), [
    ("gpCh[0].nothing", 1, "ADS 0x710"),
    ("gpCh[0].spindle.override_w", 2,
     "gpCh[0].spindle.override_w is UINT, not a struct: read it with "
     "plc.read_by_name('gpCh[0].spindle.override_w', pyads.PLCTYPE_UINT)"),
])
def test_an_unknown_name_or_not_a_struct_is_one_line(ads: Plc, name: str, code: int,
                                                     says: str) -> None:
    result = cnc("ads", "structure-def", name, endpoint=ads.service.endpoint)
    assert (result.returncode, result.stdout) == (code, "")
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and says in lines[0]


def test_docs_show_the_output_as_it_is(ads: Plc) -> None:
    """docs/ads.md's ``console`` blocks of ``cnc ads structure-def`` are the output."""
    blocks = re.findall(r"^```console\n\$ cnc ads structure-def '([^']+)'\n(.*?)^```$",
                        DOCS.read_text(), re.MULTILINE | re.DOTALL)
    assert len(blocks) == 2
    for name, shown in blocks:
        result = cnc("ads", "structure-def", name, endpoint=ads.service.endpoint)
        assert (result.stdout or result.stderr) == shown, name
