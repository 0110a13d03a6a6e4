"""The operator data file format: what ``dumps`` writes ``loads`` reads back, one row a
line; every fault is named with its place."""

from __future__ import annotations

import json

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cnc_objects.objects.operator_data import (
    VALUE_MAX_MM,
    ChannelData,
    OffsetGroup,
    OperatorData,
    OperatorDataError,
    ToolRow,
    dumps,
    loads,
)

mm = st.floats(-VALUE_MAX_MM, VALUE_MAX_MM, allow_nan=False)
rows = st.lists(st.builds(ToolRow, st.integers(1, 9999), st.booleans(),
                          st.floats(0, VALUE_MAX_MM, allow_nan=False), mm),
                unique_by=lambda r: r.wz, max_size=5)
groups = st.lists(st.builds(OffsetGroup, st.integers(1, 96),
                            st.dictionaries(st.sampled_from("XYZABC"), mm, max_size=3)),
                  unique_by=lambda g: g.np_grp, max_size=4)
channels = st.lists(st.builds(ChannelData, st.integers(1, 12), st.none() | rows.map(tuple),
                              st.none() | groups.map(tuple)),
                    unique_by=lambda c: c.channel, max_size=3)


@given(channels)
def test_what_dumps_writes_loads_reads_back(listed: list[ChannelData]) -> None:
    data = OperatorData(tuple(listed))
    text = dumps(data)
    assert loads(text) == data
    json.loads(text)  # plain JSON for every other tool too


def test_one_row_a_line() -> None:
    text = dumps(OperatorData((ChannelData(1, (ToolRow(5, True, 3.0, 42.0),),
                                           (OffsetGroup(2, {"X": 100.0}),)),)))
    assert '    {"wz": 5, "valid": true, "radius_mm": 3.0, "length_mm": 42.0}\n' in text
    assert '{"np_grp": 2, "name": "G55", "offsets_mm": {"X": 100.0}}' in text


def test_name_wear_and_life_are_written_where_set_and_read_back() -> None:
    row = ToolRow(5, True, 3.0, 42.0, "drill 6", 0.02, 600.0)
    text = dumps(OperatorData((ChannelData(1, (row,)),)))
    assert ('"wz": 5, "valid": true, "radius_mm": 3.0, "length_mm": 42.0, "name": "drill 6", '
            '"wear_mm": 0.02, "life_max_s": 600.0}') in text
    assert loads(text).channels[0].tools == (row,)


HEAD = '{"format": "cnc-objects operator data", "version": 1, "channels": '


@pytest.mark.parametrize(("text", "words"), [
    ("", "not JSON"),
    ("[]", '"format" must be'),
    ('{"format": "cnc-objects operator data", "version": 2}', "version 2"),
    (HEAD + "{}}", '"channels" must be a list'),
    (HEAD + '[{"channel": 0}]}', "channels[0].channel: a whole number >= 1"),
    (HEAD + '[{"channel": 1}, {"channel": 1}]}', "a channel is listed twice"),
    (HEAD + '[{"channel": 1, "tools": [{"wz": 1, "valid": 1}]}]}', "tools[0].valid: true"),
    (HEAD + '[{"channel": 1, "tools": [{"wz": 1, "length_mm": "4"}]}]}',
     "channels[0].tools[0].length_mm: a number of mm"),
    (HEAD + '[{"channel": 1, "tools": [{"wz": 1, "length_mm": 1e9}]}]}', "is outside"),
    (HEAD + '[{"channel": 1, "tools": [{"wz": 1}, {"wz": 1}]}]}', "a wz is listed twice"),
    (HEAD + '[{"channel": 1, "tools": [{"wz": 1, "name": 7}]}]}', "tools[0].name: text of at most 31"),
    (HEAD + '[{"channel": 1, "tools": [{"wz": 1, "life_max_s": -1}]}]}', "life_max_s: seconds in 0..1e+09"),
    (HEAD + '[{"channel": 1, "tools": [{"wz": 1, "wear_mm": "x"}]}]}', "wear_mm: a number of mm"),
    (HEAD + '[{"channel": 1, "zero_offsets": [{"np_grp": 1}]}]}', "offsets_mm: an object"),
    (HEAD + '[{"channel": 1, "zero_offsets": [{"np_grp": 1, "offsets_mm": {"X": NaN}}]}]}',
     "offsets_mm.X: a number of mm"),
])
def test_faults_are_named(text: str, words: str) -> None:
    with pytest.raises(OperatorDataError) as raised:
        loads(text)
    assert words in str(raised.value)
