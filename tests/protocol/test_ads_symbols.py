"""Symbol information on the wire (protocol/ads_symbols.py): TwinCAT type names and ADST
ids of the ISG types, AdsSymbolEntry, AdsDatatypeEntry, the three upload info forms.

Layouts are checked field by field against bytes built here from Beckhoff's header
layout (TcAdsDef.h / AdsDef.h), decoders against entries laid out as TwinCAT sends them
(with trailing bytes the decoder must skip), and everything by hypothesis round trips.
"""

from __future__ import annotations

import struct

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cnc_objects.protocol.ads_symbols import (
    ENTRY_ALIGNMENT,
    AdsDataType,
    AdsDataTypeFlag,
    AdsSymbolFlag,
    DataTypeEntry,
    SymbolEntry,
    SymbolGroup,
    SymbolUploadFlag,
    TwinCatType,
    UploadInfo,
    decode_datatype_entries,
    decode_datatype_entry,
    decode_handle_info,
    decode_symbol_entries,
    decode_symbol_entry,
    decode_upload_info,
    encode_datatype_entry,
    encode_handle_info,
    encode_symbol_entry,
    encode_symbol_version,
    encode_upload_info,
    isg_type,
    parse_twincat_type,
    twincat_type,
)
from cnc_objects.protocol.constants import ReservedIndexGroup
from cnc_objects.protocol.datatypes import SCALAR_TYPES, STRING

u32 = st.integers(min_value=0, max_value=0xFFFF_FFFF)
cp1252_text = st.text(
    alphabet=st.characters(codec="cp1252", exclude_characters="\x00"), max_size=40
)


def le32(*values: int) -> bytes:
    return struct.pack(f"<{len(values)}I", *values)


def le16(*values: int) -> bytes:
    return struct.pack(f"<{len(values)}H", *values)


# ----------------------------------------------------------------------------- constants


def test_ads_data_type_ids_are_the_adst_values() -> None:
    # TcAdsDef.h ADST_*: the numbers clients switch on
    assert {t.name: t.value for t in AdsDataType} == {
        "VOID": 0, "INT16": 2, "INT32": 3, "REAL32": 4, "REAL64": 5, "INT8": 16,
        "UINT8": 17, "UINT16": 18, "UINT32": 19, "INT64": 20, "UINT64": 21, "STRING": 30,
        "WSTRING": 31, "REAL80": 32, "BIT": 33, "BIGTYPE": 65,
    }


def test_ads_data_type_ids_agree_with_pyads() -> None:
    constants = pytest.importorskip("pyads.constants")
    for member in AdsDataType:
        assert getattr(constants, f"ADST_{member.name}") == member.value, member


def test_symbol_flags_are_the_adssymbolflag_values() -> None:
    # AdsDef.h: PERSISTENT 1<<0, BITVALUE 1<<1, REFERENCETO 1<<2, TYPEGUID 1<<3,
    # TCCOMIFACEPTR 1<<4, READONLY 1<<5, CONTEXTMASK 0xF00
    assert AdsSymbolFlag.PERSISTENT == 0x1
    assert AdsSymbolFlag.BITVALUE == 0x2
    assert AdsSymbolFlag.REFERENCETO == 0x4
    assert AdsSymbolFlag.TYPEGUID == 0x8
    assert AdsSymbolFlag.TCCOMIFACEPTR == 0x10
    assert AdsSymbolFlag.READONLY == 0x20
    assert AdsSymbolFlag.CONTEXTMASK == 0xF00
    assert AdsDataTypeFlag.DATATYPE == 0x1 and AdsDataTypeFlag.DATAITEM == 0x2


def test_symbol_groups_are_the_reserved_index_groups() -> None:
    assert [(g.name, g.value) for g in SymbolGroup] == [
        ("INFO_BY_NAME", 0xF007), ("VERSION", 0xF008), ("INFO_BY_NAME_EX", 0xF009),
        ("UPLOAD", 0xF00B), ("UPLOAD_INFO", 0xF00C), ("DT_UPLOAD", 0xF00E),
        ("UPLOAD_INFO2", 0xF00F), ("DT_INFO_BY_NAME_EX", 0xF011),
    ]
    assert SymbolUploadFlag.IS_64BIT_PLATFORM == 1 and SymbolUploadFlag.INCLUDES_BASE_TYPES == 2


def test_symbol_groups_agree_with_the_reserved_index_groups_of_constants() -> None:
    # the vocabulary lists the same groups as ReservedIndexGroup.SYM_*; where both
    # name a group they must agree
    shared = [g for g in SymbolGroup if hasattr(ReservedIndexGroup, f"SYM_{g.name}")]
    for group in shared:
        assert getattr(ReservedIndexGroup, f"SYM_{group.name}") == group


# ----------------------------------------------------------------------------- type mapping

EXPECTED_SCALARS = {
    "BOOLEAN": ("BOOL", 33, 1),
    "UNS08": ("USINT", 17, 1),
    "SGN08": ("SINT", 16, 1),
    "UNS16": ("UINT", 18, 2),
    "SGN16": ("INT", 2, 2),
    "UNS32": ("UDINT", 19, 4),
    "SGN32": ("DINT", 3, 4),
    "UNS64": ("ULINT", 21, 8),
    "SGN64": ("LINT", 20, 8),
    "REAL32": ("REAL", 4, 4),
    "REAL64": ("LREAL", 5, 8),
}


@pytest.mark.parametrize("isg", sorted(EXPECTED_SCALARS))
def test_scalar_types_map_to_twincat_names_and_adst_ids(isg: str) -> None:
    dtype = SCALAR_TYPES[isg]
    name, ads, size = EXPECTED_SCALARS[isg]
    assert twincat_type(dtype) == TwinCatType(name, AdsDataType(ads), size)
    assert name == dtype.iec  # the IEC name datatypes.py already carries
    assert isg_type(name) is dtype
    assert isg_type(name.lower()) is dtype


def test_every_isg_scalar_has_a_mapping() -> None:
    assert set(EXPECTED_SCALARS) == set(SCALAR_TYPES)


@pytest.mark.parametrize("size", [2, 16, 84, 256, 4096, 65536])
def test_string_n_is_twincat_string_n_minus_1_of_n_bytes(size: int) -> None:
    # ISG STRING(n): n bytes with the NUL; TwinCAT STRING(k): k characters + NUL
    tc = twincat_type(STRING(size))
    assert tc == TwinCatType(f"STRING({size - 1})", AdsDataType.STRING, size)
    assert isg_type(tc.name) is STRING(size)


def test_string_of_no_characters_has_no_twincat_name() -> None:
    # ISG STRING(1) holds only the NUL; TwinCAT has no STRING(0)
    assert twincat_type(STRING(1)).name == "STRING(0)"
    with pytest.raises(ValueError):
        parse_twincat_type("STRING(0)")


def test_twincat_type_names_parse_in_any_case_and_spacing() -> None:
    assert parse_twincat_type("string") == TwinCatType("STRING(80)", AdsDataType.STRING, 81)
    assert parse_twincat_type(" String ( 83 ) ") == TwinCatType(
        "STRING(83)", AdsDataType.STRING, 84
    )
    assert parse_twincat_type("lreal") == TwinCatType("LREAL", AdsDataType.REAL64, 8)
    assert parse_twincat_type("WORD") == TwinCatType("WORD", AdsDataType.UINT16, 2)
    assert parse_twincat_type("lword") == TwinCatType("LWORD", AdsDataType.UINT64, 8)
    assert isg_type("DWORD") is SCALAR_TYPES["UNS32"]
    assert isg_type("BYTE") is SCALAR_TYPES["UNS08"]


@pytest.mark.parametrize(
    "name", ["", "TIME", "WSTRING", "STRING(65536)", "STRING(-1)", "ARRAY [0..1] OF INT", "UDINTX"]
)
def test_unknown_twincat_type_names_are_refused(name: str) -> None:
    with pytest.raises(ValueError):
        parse_twincat_type(name)


# ----------------------------------------------------------------------------- symbol entry


def test_symbol_entry_layout_field_by_field() -> None:
    entry = SymbolEntry(
        0x4020, 0x10040, 4, AdsDataType.UINT32, AdsSymbolFlag.READONLY,
        "gpCh[0].a", "UDINT", "count of blocks",
    )
    data = encode_symbol_entry(entry)
    content = 30 + len("gpCh[0].a") + 1 + len("UDINT") + 1 + len("count of blocks") + 1
    assert content == 62
    assert len(data) == 64  # padded to a multiple of 8
    assert data[0:4] == le32(64)  # entryLength counts the padding
    assert data[4:8] == le32(0x4020)  # iGroup
    assert data[8:12] == le32(0x10040)  # iOffs
    assert data[12:16] == le32(4)  # size
    assert data[16:20] == le32(19)  # dataType ADST_UINT32
    assert data[20:24] == le32(0x20)  # flags READONLY
    assert data[24:30] == le16(9, 5, 15)  # name, type, comment lengths without NUL
    assert data[30:62] == b"gpCh[0].a\x00UDINT\x00count of blocks\x00"
    assert data[62:] == b"\x00\x00"


def test_symbol_entry_already_aligned_gets_no_padding() -> None:
    # 30 + 1+1 + 1+1 + 1+1 = 36 -> 40; 30 + 5+1 + 1+1 + 2 = 40 -> 40
    assert len(encode_symbol_entry(SymbolEntry(0, 0, 1, 33, 0, "abcde", "B", "c"))) == 40
    assert len(encode_symbol_entry(SymbolEntry(0, 0, 1, 33, 0, "a", "B", "c"))) == 40


def test_decode_symbol_entry_as_twincat_sends_it_with_a_type_guid() -> None:
    # pyads documents a TwinCAT 3 entry: name 11, type 4, comment 20 chars, flags 8
    # (TYPEGUID): 84 bytes of content, entryLength 88. The decoder skips what follows.
    body = (
        le32(0x4040, 385000, 2, 18, 8) + le16(11, 4, 20)
        + b"GVL.counter\x00UINT\x00 Counter (in pulses)\x00" + bytes(range(16))
    )
    raw = le32(88) + body + bytes(88 - 4 - len(body))
    entry, length = decode_symbol_entry(raw + b"next")
    assert length == 88
    assert entry == SymbolEntry(0x4040, 385000, 2, 18, 8, "GVL.counter", "UINT", " Counter (in pulses)")


@pytest.mark.parametrize(
    "raw",
    [
        b"",  # nothing
        le32(40) + bytes(20),  # shorter than a header
        le32(20) + bytes(36),  # entry length below the header size
        le32(48) + bytes(36),  # entry length beyond the data
        le32(40) + le32(0, 0, 0, 0, 0) + le16(5, 0, 0) + b"abcdefghij",  # name lacks its NUL
        le32(40) + le32(0, 0, 0, 0, 0) + le16(9, 0, 0) + bytes(10),  # strings overrun the entry
    ],
)
def test_malformed_symbol_entries_are_refused(raw: bytes) -> None:
    with pytest.raises(ValueError):
        decode_symbol_entry(raw)


def test_symbol_entry_strings_are_cp1252_and_bounded() -> None:
    data = encode_symbol_entry(SymbolEntry(0, 0, 8, 5, 0, "pos_µm", "LREAL", "0.1 µm → mm"))
    entry, _ = decode_symbol_entry(data)
    assert entry.name == "pos_µm"  # CP1252 has µ
    assert entry.comment == "0.1 µm ? mm"  # and lacks the arrow: replaced, not refused
    with pytest.raises(ValueError):
        encode_symbol_entry(SymbolEntry(0, 0, 1, 33, 0, "a\x00b", "BOOL"))
    with pytest.raises(ValueError):
        encode_symbol_entry(SymbolEntry(0, 0, 1, 33, 0, "a", "BOOL", "x" * 65536))


symbol_entries = st.builds(
    SymbolEntry, u32, u32, u32, u32, u32, cp1252_text, cp1252_text, cp1252_text
)


@given(st.lists(symbol_entries, max_size=5))
def test_symbol_entries_round_trip(entries: list[SymbolEntry]) -> None:
    blobs = [encode_symbol_entry(e) for e in entries]
    for blob in blobs:
        assert len(blob) % ENTRY_ALIGNMENT == 0
        assert struct.unpack_from("<I", blob)[0] == len(blob)
    assert decode_symbol_entries(b"".join(blobs)) == entries


# ----------------------------------------------------------------------------- data type entry


def test_base_data_type_entry_layout_field_by_field() -> None:
    entry = DataTypeEntry("UDINT", 4, AdsDataType.UINT32, hash_value=0x12345678)
    data = encode_datatype_entry(entry)
    content = 42 + 6 + 1 + 1
    assert len(data) == 56 and content == 50
    assert data[0:4] == le32(56)  # entryLength
    assert data[4:8] == le32(1)  # version
    assert data[8:12] == le32(0x12345678)  # hashValue
    assert data[12:16] == le32(0)  # typeHashValue
    assert data[16:20] == le32(4)  # size
    assert data[20:24] == le32(0)  # offs
    assert data[24:28] == le32(19)  # dataType
    assert data[28:32] == le32(AdsDataTypeFlag.DATATYPE)  # flags
    assert data[32:42] == le16(5, 0, 0, 0, 0)  # name, type, comment lengths, arrayDim, subItems
    assert data[42:50] == b"UDINT\x00\x00\x00"
    assert data[50:] == bytes(6)


def test_structured_data_type_entry_with_array_and_sub_items() -> None:
    flag = DataTypeEntry("bFlag", 1, 33, AdsDataTypeFlag.DATAITEM, "BOOL", offset=0)
    values = DataTypeEntry(
        "aValue", 8, 2, AdsDataTypeFlag.DATAITEM, "ARRAY [1..4] OF INT", offset=2,
        array=((1, 4),),
    )
    struct_type = DataTypeEntry("ST_Test", 10, 65, sub_items=(flag, values), comment="test")
    data = encode_datatype_entry(struct_type)
    assert data[32:42] == le16(7, 0, 4, 0, 2)
    at = 42 + 8 + 1 + 5
    assert data[42:at] == b"ST_Test\x00\x00test\x00"
    first = decode_datatype_entry(data, at)
    assert first == (flag, struct.unpack_from("<I", data, at)[0])
    second_at = at + first[1]
    array_at = second_at + 42 + len("aValue\0ARRAY [1..4] OF INT\0\0")
    assert struct.unpack_from("<II", data, array_at) == (1, 4)  # lBound, element count
    assert decode_datatype_entry(data) == (struct_type, len(data))


def test_decode_data_type_entry_skips_trailing_type_guid_and_copy_mask() -> None:
    body = (
        le32(1, 0, 0, 2, 0, 18, AdsDataTypeFlag.DATATYPE | AdsDataTypeFlag.TYPEGUID)
        + le16(4, 0, 0, 0, 0) + b"WORD\x00\x00\x00" + bytes(16) + b"\xff\xff"
    )
    raw = le32(4 + len(body)) + body
    entry, length = decode_datatype_entry(raw)
    assert length == len(raw)
    assert (entry.name, entry.size, entry.data_type) == ("WORD", 2, 18)


def test_sub_item_that_overruns_its_parent_is_refused() -> None:
    child = encode_datatype_entry(DataTypeEntry("a", 1, 33, AdsDataTypeFlag.DATAITEM, "BOOL"))
    parent = encode_datatype_entry(DataTypeEntry("ST", 1, 65, sub_items=(
        DataTypeEntry("a", 1, 33, AdsDataTypeFlag.DATAITEM, "BOOL"),
    )))
    # shrink the parent's entry length so that the child no longer fits inside it
    shrunk = le32(len(parent) - len(child)) + parent[4:]
    with pytest.raises(ValueError):
        decode_datatype_entry(shrunk)
    # and claim two sub items where one is present
    with pytest.raises(ValueError):
        decode_datatype_entry(parent[:40] + le16(2) + parent[42:])


def test_data_type_entry_with_more_dimensions_than_room_is_refused() -> None:
    data = encode_datatype_entry(DataTypeEntry("A", 2, 65))
    with pytest.raises(ValueError):
        decode_datatype_entry(data[:38] + le16(3) + data[40:])


leaf_types = st.builds(
    DataTypeEntry, cp1252_text, u32, u32, u32, cp1252_text, cp1252_text, u32, u32, u32, u32,
    st.lists(st.tuples(u32, u32), max_size=3).map(tuple),
)
data_types = st.recursive(
    leaf_types,
    lambda children: st.builds(
        DataTypeEntry, cp1252_text, u32, u32, u32, cp1252_text, cp1252_text, u32,
        sub_items=st.lists(children, max_size=3).map(tuple),
    ),
    max_leaves=8,
)


@given(st.lists(data_types, max_size=4))
def test_data_type_entries_round_trip(entries: list[DataTypeEntry]) -> None:
    blobs = [encode_datatype_entry(e) for e in entries]
    assert all(len(b) % ENTRY_ALIGNMENT == 0 for b in blobs)
    assert decode_datatype_entries(b"".join(blobs)) == entries


# ----------------------------------------------------------------------------- upload info

INFO = UploadInfo(999, 149688, 11, 624, 7, 3, 2, 1252, SymbolUploadFlag.INCLUDES_BASE_TYPES)


def test_upload_info_8_bytes_is_count_and_size() -> None:
    assert encode_upload_info(INFO, 8) == le32(999, 149688)


def test_upload_info2_24_bytes_adds_types_and_dynamic_symbols() -> None:
    assert encode_upload_info(INFO, 24) == le32(999, 149688, 11, 624, 7, 3)


def test_upload_info_64_bytes_adds_code_page_flags_and_reserve() -> None:
    data = encode_upload_info(INFO, 64)
    assert data == le32(999, 149688, 11, 624, 7, 3, 2, 1252, 2) + bytes(28)


def test_upload_info_decodes_each_form_by_its_length() -> None:
    assert decode_upload_info(encode_upload_info(INFO, 64)) == INFO
    assert decode_upload_info(le32(5, 6, 7, 8, 9, 10)) == UploadInfo(5, 6, 7, 8, 9, 10)
    assert decode_upload_info(le32(5, 6)) == UploadInfo(5, 6)


@pytest.mark.parametrize("size", [0, 4, 12, 32, 65])
def test_upload_info_has_three_sizes_only(size: int) -> None:
    with pytest.raises(ValueError):
        encode_upload_info(INFO, size)
    with pytest.raises(ValueError):
        decode_upload_info(bytes(size))


@given(st.builds(UploadInfo, u32, u32, u32, u32, u32, u32, u32, u32, u32))
def test_upload_info_round_trips_in_the_64_byte_form(info: UploadInfo) -> None:
    assert decode_upload_info(encode_upload_info(info, 64)) == info
    short = decode_upload_info(encode_upload_info(info, 24))
    assert short == UploadInfo(*[getattr(info, f) for f in UploadInfo.__slots__[:6]])


def test_symbol_version_is_one_byte() -> None:
    assert encode_symbol_version(1) == b"\x01"
    assert encode_symbol_version(255) == b"\xff"
    with pytest.raises(ValueError):
        encode_symbol_version(256)


def test_extended_handle_answer_round_trip() -> None:
    data = encode_handle_info(7, 84, "STRING(83)")
    assert data[:14] == struct.pack("<IIIH", 7, 84, 0, 10) and data[14:] == b"STRING(83)\x00"
    assert decode_handle_info(data) == (7, 84, 0, "STRING(83)")
    with pytest.raises(ValueError):
        decode_handle_info(data[:-1])
