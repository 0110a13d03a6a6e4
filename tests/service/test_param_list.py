"""ISG parameter lists: good lists parse to the exact dicts, bad ones report every problem
at its line, files are read as UTF-8 or cp1252."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cnc_objects.service.param_list import (
    ParamListError,
    Problem,
    parse_axis_list,
    parse_channel_list,
    read_axis_list,
    read_channel_list,
)

DATA = Path(__file__).resolve().parents[1] / "data" / "params"


def problems_of(parse, text: str, source: str = "list.lis") -> list[tuple[int, str]]:
    """The (line, message) pairs a list is refused with; fails if it is accepted."""
    with pytest.raises(ParamListError) as caught:
        parse(text, source)
    assert all(p.file == source for p in caught.value.problems)
    return [(p.line, p.message) for p in caught.value.problems]


def assert_problems(found: list[tuple[int, str]], expected: list[tuple[int, str]]) -> None:
    """Each problem in order: its line, and a fragment of its message."""
    assert [line for line, _ in found] == [line for line, _ in expected], found
    for (line, message), (_, fragment) in zip(found, expected, strict=True):
        assert fragment in message, (line, message, fragment)


# --- good files ---------------------------------------------------------------------


def test_axis_11_clone_of_axis_1_linked_to_drive_1() -> None:
    assert read_axis_list(DATA / "axis-11.lis") == {
        "logical_number": 11,
        "link_to": 1,
        "clone_of": 1,
        "auto_release_of_axis_link": True,
        "limits": {"vel_max_mm_s": 250.0},
    }


def test_full_axis_1_list_with_limits() -> None:
    assert read_axis_list(DATA / "axis-1.lis") == {
        "logical_number": 1,
        "link_to": 1,
        "axis_type": "linear",
        "limits": {
            "sw_limit_min_mm": -1000.0,
            "sw_limit_max_mm": 1000.0,
            "vel_max_mm_s": 500.0,
            "acc_max_mm_s2": 5000.0,
        },
    }


def test_channel_2_the_jog_channel_on_clones() -> None:
    assert read_channel_list(DATA / "channel-2.lis") == {
        "axes": [
            {"name": "X", "logical_number": 11},
            {"name": "Y", "logical_number": 12},
            {"name": "Z", "logical_number": 13},
        ],
        "jog_of_path_only": True,
    }


def test_channel_1_path_axes() -> None:
    assert read_channel_list(DATA / "channel-1.lis") == {
        "axes": [
            {"name": "X", "logical_number": 1},
            {"name": "Y", "logical_number": 2},
            {"name": "Z", "logical_number": 3},
        ],
    }


def test_cp1252_file_with_crlf_is_read() -> None:
    raw = (DATA / "axis-2-cp1252.lis").read_bytes()
    with pytest.raises(UnicodeDecodeError):
        raw.decode("utf-8")  # the file really needs the fallback
    assert read_axis_list(DATA / "axis-2-cp1252.lis") == {
        "logical_number": 2,
        "link_to": 2,
        "limits": {"sw_limit_min_mm": -500.0, "sw_limit_max_mm": 500.0},
    }


# --- bad files ----------------------------------------------------------------------


def test_bad_axis_list_reports_every_problem_at_its_line() -> None:
    path = DATA / "axis-bad.lis"
    with pytest.raises(ParamListError) as caught:
        read_axis_list(path)
    assert all(p.file == str(path) for p in caught.value.problems)
    assert_problems([(p.line, p.message) for p in caught.value.problems], [
        (2, "kopf.achs_nr (P-AXIS-00016): 70000 is out of range 1..65535"),
        (3, "kopf.link_to (P-AXIS-00101): the value is missing"),
        (5, "kopf.clone_of given twice, first at line 4"),
        (6, "kenngr.auto_release_of_axis_link (P-AXIS-00483): '2' is not a BOOLEAN"),
        (7, "spindle axes cannot be cloned (kopf.clone_of, P-AXIS-00040)"),
        (8, "kenngr.swe_neg (P-AXIS-00177): '-1e6' is not an integer"),
        (9, "unknown key 'kenngr.referenz' (supported: kopf.achs_nr, kopf.link_to, "
            "kopf.clone_of, kenngr.auto_release_of_axis_link, kenngr.achs_typ, kenngr.swe_neg, "
            "kenngr.swe_pos, kenngr.swe_check, getriebe[0].dynamik.vb_max, "
            "getriebe[0].dynamik.a_max)"),
        (10, "only getriebe[0] (gear stage 0) is supported"),
        (11, "malformed key 'getriebe[0.dynamik.a_max'"),
        (12, "getriebe[0].dynamik.a_max (P-AXIS-00008): 0 is out of range 1..4294967295"),
        (13, "kenngr.swe_pos (P-AXIS-00178): 0x80000000 is out of range "
             "-2147483648..2147483647"),
    ])
    # str(err): one problem a line, each "file:line: message".
    lines = str(caught.value).split("\n")
    assert len(lines) == 11
    assert lines[0] == f"{path}:2: kopf.achs_nr (P-AXIS-00016): 70000 is out of range 1..65535"


def test_rotary_axis_and_missing_achs_nr() -> None:
    with pytest.raises(ParamListError) as caught:
        read_axis_list(DATA / "axis-rotary.lis")
    assert [(p.line, p.message) for p in caught.value.problems] == [
        (0, "kopf.achs_nr is missing (P-AXIS-00016, required)"),
    ]


def test_bad_channel_list_reports_every_problem_at_its_line() -> None:
    with pytest.raises(ParamListError) as caught:
        read_channel_list(DATA / "channel-bad.lis")
    assert_problems([(p.line, p.message) for p in caught.value.problems], [
        (2, "gruppe[0].achs_anzahl (P-CHAN-00003) is 4 but 5 axes are listed"),
        (5, "gruppe[0].achse[1].log_achs_nr: 1 repeats the log_achs_nr of gruppe[0].achse[0] "
            "(line 3)"),
        (6, "'X1' is a valid ISG axis name, but this kernel's NC decoder takes single-letter"),
        (7, "gruppe[0].achse[3] leaves a gap: no gruppe[0].achse[2]"),
        (7, "gruppe[0].achse[3] has log_achs_nr but no bezeichnung"),
        (8, "malformed key 'gruppe[x].achse[0].bezeichnung'"),
        (9, "gruppe[1].achs_anzahl: only gruppe[0] is supported"),
        (10, "jog_of_path_only (P-CHAN-00306): 'yes' is not a BOOLEAN (0 or 1)"),
        (11, "gruppe[0].achse[0].bezeichnung given twice, first at line 4"),
        (13, "gruppe[0].achse[4].bezeichnung: X repeats the bezeichnung of gruppe[0].achse[0] "
             "(line 4)"),
        (14, "gruppe[0].achse[5].log_achs_nr (P-CHAN-00035): 0x10000 is out of range 1..65535"),
        (14, "gruppe[0].achse[5] has log_achs_nr but no bezeichnung"),
    ])


# --- files: missing, undecodable, BOM, cp1252 ---------------------------------------


def test_missing_file_names_the_path(tmp_path: Path) -> None:
    path = tmp_path / "no-such-list.lis"
    for read in (read_axis_list, read_channel_list):
        with pytest.raises(ParamListError) as caught:
            read(path)
        (problem,) = caught.value.problems
        assert (problem.file, problem.line) == (str(path), 0)
        assert "cannot read the file" in problem.message
        assert str(caught.value).startswith(f"{path}:0: ")


def test_directory_is_an_unreadable_file(tmp_path: Path) -> None:
    with pytest.raises(ParamListError) as caught:
        read_axis_list(tmp_path)
    assert [(p.file, p.line) for p in caught.value.problems] == [(str(tmp_path), 0)]


def test_cp1252_fallback_decodes_cp1252_not_latin1(tmp_path: Path) -> None:
    # 0x80 is the euro sign in cp1252 (a control character in latin-1); the refused key
    # is quoted in the message, so the message shows how the bytes were decoded.
    path = tmp_path / "axis.lis"
    path.write_bytes("kopf.achs_nr 1\ngr\u00f6\u00dfe\u20ac 1\n".encode("cp1252"))
    with pytest.raises(ParamListError) as caught:
        read_axis_list(path)
    ((line, message),) = [(p.line, p.message) for p in caught.value.problems]
    assert line == 2 and "'gr\u00f6\u00dfe\u20ac'" in message


def test_utf8_is_preferred_and_a_bom_is_dropped(tmp_path: Path) -> None:
    path = tmp_path / "channel.lis"
    path.write_bytes("\ufeff# Kanal für X\njog_of_path_only 1\n".encode())
    assert read_channel_list(path) == {"jog_of_path_only": True}
    path.write_bytes("jog_of_path_only 1\nx\u00b5 1\n".encode())  # µ: two bytes in UTF-8
    with pytest.raises(ParamListError) as caught:
        read_channel_list(path)
    assert "'x\u00b5'" in caught.value.problems[0].message


def test_neither_utf8_nor_cp1252_names_the_line(tmp_path: Path) -> None:
    path = tmp_path / "axis.lis"
    path.write_bytes(b"kopf.achs_nr 1\n# \x81\n")  # 0x81 is undefined in cp1252
    with pytest.raises(ParamListError) as caught:
        read_axis_list(path)
    assert [(p.line, p.message) for p in caught.value.problems] == [
        (2, "neither UTF-8 nor cp1252 text (byte 0x81)")
    ]


# --- the line format ----------------------------------------------------------------


def test_comments_blank_lines_tabs_crlf_and_case() -> None:
    text = (
        "# whole-line comment\r\n"
        "\r\n"
        "   \t  \r\n"
        "  KOPF.ACHS_NR\t\t 7   # keys are matched case-insensitively\r\n"
        "Kopf.Link_To 0x0003#comment right after the value\r\n"
        "kenngr.achs_typ achstyp_translator\r\n"
        "getriebe[000].dynamik.a_max +250\r\n"
    )
    assert parse_axis_list(text, "x") == {
        "logical_number": 7,
        "link_to": 3,
        "axis_type": "linear",
        "limits": {"acc_max_mm_s2": 250.0},
    }


def test_empty_lists() -> None:
    assert parse_channel_list("", "c") == {}
    assert parse_channel_list("# nothing\n\n", "c") == {}
    assert problems_of(parse_axis_list, "# nothing\n") == [
        (0, "kopf.achs_nr is missing (P-AXIS-00016, required)")
    ]


def test_only_present_keys_appear() -> None:
    assert parse_axis_list("kopf.achs_nr 5", "a") == {"logical_number": 5}
    assert parse_axis_list("kopf.achs_nr 5\nkenngr.swe_pos 1", "a") == {
        "logical_number": 5,
        "limits": {"sw_limit_max_mm": 0.0001},
    }
    assert parse_channel_list("jog_of_path_only 0", "c") == {"jog_of_path_only": False}


def test_repeat_written_with_other_case_or_padded_index_is_caught() -> None:
    text = "kopf.achs_nr 1\ngetriebe[0].dynamik.a_max 1\nGETRIEBE[00].DYNAMIK.A_MAX 2\n"
    assert problems_of(parse_axis_list, text) == [
        (3, "getriebe[0].dynamik.a_max given twice, first at line 2")
    ]


def test_a_missing_value_still_counts_as_given() -> None:
    # No second "kopf.achs_nr is missing": the key is there, only its value is not.
    assert problems_of(parse_axis_list, "kopf.achs_nr\n") == [
        (1, "kopf.achs_nr (P-AXIS-00016): the value is missing")
    ]


@pytest.mark.parametrize(
    ("line", "fragment"),
    [
        ("kopf.achs_nr 1 2", "one value expected, found '1 2'"),
        ("kopf.achs_nr 0", "0 is out of range 1..65535"),
        ("kopf.achs_nr 65536", "65536 is out of range 1..65535"),
        ("kopf.achs_nr -0x1", "'-0x1' is not an integer"),
        ("kopf.achs_nr 1_000", "'1_000' is not an integer"),
        ("kopf.achs_nr \u0661", "'\u0661' is not an integer"),  # an Arabic-Indic digit
        ("kopf.achs_nr 0x", "'0x' is not an integer"),
        ("kenngr.auto_release_of_axis_link 0x1", "'0x1' is not a BOOLEAN (0 or 1)"),
        ("kenngr.auto_release_of_axis_link true", "'true' is not a BOOLEAN"),
        ("kenngr.swe_neg -2147483649", "out of range -2147483648..2147483647"),
        ("getriebe[0].dynamik.vb_max 4294967296", "out of range 1..4294967295"),
        ("kenngr.achs_typ 3", "'3' is not an axis type"),
        ("kenngr.achs_typ ACHSTYP_LINEAR", "'ACHSTYP_LINEAR' is not an axis type"),
        ("kopf[0].achs_nr 1", "unknown key 'kopf[0].achs_nr'"),
        ("getriebe.dynamik.vb_max 1", "unknown key 'getriebe.dynamik.vb_max'"),
        ("getriebe[2].dynamik.a_max 1", "only getriebe[0] (gear stage 0) is supported"),
        ("kopf..achs_nr 1", "malformed key 'kopf..achs_nr'"),
        ("kopf.achs_nr] 1", "malformed key"),
        ("getriebe[-1].dynamik.a_max 1", "malformed key"),
        ("getriebe[ 0].dynamik.a_max 1", "malformed key"),
        (".kopf 1", "malformed key"),
        ("kopf.achs_nr=1", "malformed key 'kopf.achs_nr=1'"),
        ("k\u212aopf.achs_nr 1", "malformed key"),  # Kelvin sign: no ASCII letter
    ],
)
def test_bad_axis_lines(line: str, fragment: str) -> None:
    found = problems_of(parse_axis_list, f"kopf.clone_of 1\n{line}\n")
    messages = [message for number, message in found if number == 2]
    assert len(messages) == 1 and fragment in messages[0], found


@pytest.mark.parametrize("value", ["ACHSTYP_TRANSLATOR", "achstyp_translator", "1", "0x0001"])
def test_linear_axis_type(value: str) -> None:
    assert parse_axis_list(f"kopf.achs_nr 1\nkenngr.achs_typ {value}", "a") == {
        "logical_number": 1,
        "axis_type": "linear",
    }


@pytest.mark.parametrize("value", ["ACHSTYP_ROTATOR", "2", "0x0002"])
def test_rotary_axis_type(value: str) -> None:
    assert parse_axis_list(f"kopf.achs_nr 1\nkenngr.achs_typ {value}", "a") == {
        "logical_number": 1,
        "axis_type": "rotary",
    }


@pytest.mark.parametrize("value", ["ACHSTYP_SPINDEL", "4", "0x0004"])
def test_spindle_axis_type(value: str) -> None:
    text = f"kopf.achs_nr 1\nkenngr.achs_typ {value}"
    assert problems_of(parse_axis_list, text) == [
        (2, "spindle axes (kenngr.achs_typ 4) are not supported by this kernel")
    ]
    # The clone problem replaces the plain one, wherever kopf.clone_of stands.
    assert problems_of(parse_axis_list, f"{text}\nkopf.clone_of 9") == [
        (2, "spindle axes cannot be cloned (kopf.clone_of, P-AXIS-00040)")
    ]


def test_problem_and_error_text() -> None:
    problem = Problem("axis.lis", 4, "something")
    assert str(problem) == "axis.lis:4: something"
    error = ParamListError([Problem("a", 3, "later"), Problem("a", 0, "whole"),
                            Problem("a", 3, "same line, found second")])
    assert isinstance(error, ValueError)
    assert error.problems == (Problem("a", 0, "whole"), Problem("a", 3, "later"),
                              Problem("a", 3, "same line, found second"))
    assert str(error) == "a:0: whole\na:3: later\na:3: same line, found second"


# --- channel lists ------------------------------------------------------------------


def channel(*axis_lines: str, count: int | None = None) -> str:
    head = [] if count is None else [f"gruppe[0].achs_anzahl {count}"]
    return "\n".join([*head, *axis_lines]) + "\n"


def test_channel_names_are_capitalised_and_in_index_order() -> None:
    text = channel(
        "gruppe[0].achse[1].bezeichnung q",
        "gruppe[0].achse[1].log_achs_nr 0x20",
        "gruppe[0].achse[0].log_achs_nr 7",
        "gruppe[0].achse[0].bezeichnung A",
        count=2,
    )
    assert parse_channel_list(text, "c") == {
        "axes": [{"name": "A", "logical_number": 7}, {"name": "Q", "logical_number": 32}]
    }


@pytest.mark.parametrize(
    ("name", "fragment"),
    [
        ("K", "'K' is not an axis name (a letter A B C Q U V W X Y Z"),
        ("1X", "'1X' is not an axis name"),
        ("X-1", "'X-1' is not an axis name"),
        ("X" * 16, "is not an axis name"),
        ("\u00c4", "is not an axis name"),
        ("X\u0131", "is not an axis name"),  # dotless i: no ASCII letter, though I in capitals
        ("X_ACHSE1", "'X_ACHSE1' is a valid ISG axis name, but this kernel's NC decoder takes "
                     "single-letter axis names only"),
        ("W1", "'W1' is a valid ISG axis name"),
        ("X" * 15, "is a valid ISG axis name"),
    ],
)
def test_bad_axis_names(name: str, fragment: str) -> None:
    text = channel(f"gruppe[0].achse[0].bezeichnung {name}", "gruppe[0].achse[0].log_achs_nr 1",
                   count=1)
    found = problems_of(parse_channel_list, text)
    assert len(found) == 1 and found[0][0] == 2 and fragment in found[0][1], found


def test_achs_anzahl_is_required_with_axes_and_ranged() -> None:
    axes = ("gruppe[0].achse[0].log_achs_nr 1", "gruppe[0].achse[0].bezeichnung X")
    assert problems_of(parse_channel_list, channel(*axes)) == [
        (0, "gruppe[0].achs_anzahl is missing (P-CHAN-00003, required with axes)")
    ]
    found = problems_of(parse_channel_list, channel(*axes, count=33))
    assert found == [(1, "gruppe[0].achs_anzahl (P-CHAN-00003): 33 is out of range 1..32")]
    # achs_anzahl without any achse entry: a mismatch, not an empty axis list.
    assert problems_of(parse_channel_list, channel(count=2)) == [
        (1, "gruppe[0].achs_anzahl (P-CHAN-00003) is 2 but 0 axes are listed "
            "(gruppe[0].achse[...])")
    ]


def test_gaps_are_reported_once_each_with_their_span() -> None:
    text = channel(
        "gruppe[0].achse[2].log_achs_nr 3", "gruppe[0].achse[2].bezeichnung Z",
        "gruppe[0].achse[6].log_achs_nr 7", "gruppe[0].achse[6].bezeichnung W",
        count=2,
    )
    # Two axes, two counted: only the gaps are wrong.
    assert_problems(problems_of(parse_channel_list, text), [
        (2, "gruppe[0].achse[2] leaves a gap: no gruppe[0].achse[0..1] "),
        (4, "gruppe[0].achse[6] leaves a gap: no gruppe[0].achse[3..5] "),
    ])
    text = channel("gruppe[0].achse[0].log_achs_nr 1", "gruppe[0].achse[0].bezeichnung X",
                   "gruppe[0].achse[2].log_achs_nr 3", "gruppe[0].achse[2].bezeichnung Z",
                   count=2)
    assert_problems(problems_of(parse_channel_list, text), [
        (4, "gruppe[0].achse[2] leaves a gap: no gruppe[0].achse[1] "),
    ])


def test_an_axis_without_log_achs_nr_is_reported_at_its_name() -> None:
    text = channel("gruppe[0].achse[0].log_achs_nr 1", "gruppe[0].achse[0].bezeichnung X",
                   "gruppe[0].achse[1].bezeichnung Y", count=2)
    assert problems_of(parse_channel_list, text) == [
        (4, "gruppe[0].achse[1] has bezeichnung but no log_achs_nr (both are needed)")
    ]


def test_unknown_channel_key_lists_the_supported_ones() -> None:
    assert problems_of(parse_channel_list, "grp_anzahl 1") == [
        (1, "unknown key 'grp_anzahl' (supported: gruppe[0].achs_anzahl, "
            "gruppe[0].achse[n].log_achs_nr, gruppe[0].achse[n].bezeichnung, jog_of_path_only, "
            "syn_chk.errors_total, syn_chk.fehler_gesamt, syn_chk.errors_per_block, "
            "syn_chk.fehler_pro_zeile, syn_chk.interactive, syn_chk.record_result, "
            "hscs.deselect.prog, hscs.deselect.tolerance, hscs.rough.prog, "
            "hscs.rough.tolerance, hscs.prefinish.prog, hscs.prefinish.tolerance, "
            "hscs.finish.prog, hscs.finish.tolerance)")
    ]


def test_hscs_keys_of_a_channel_list() -> None:
    parsed = parse_channel_list("hscs.finish.prog myFinish.nc\nhscs.finish.tolerance 50\n"
                                "hscs.rough.tolerance 2000\n", "ch.lis")
    assert parsed["hscs"] == {"finish": {"prog": "myFinish.nc", "tolerance": 50},
                              "rough": {"tolerance": 2000}}
    assert problems_of(parse_channel_list, "hscs.finish.prog ../x") == [
        (1, "hscs.finish.prog (hscs): '../x' is not a program name (letters, digits, _ - .)")]


# --- properties ---------------------------------------------------------------------


def spellings(number: int) -> st.SearchStrategy[str]:
    """Ways an ISG list may write a non-negative integer."""
    return st.sampled_from([
        str(number), f"+{number}", f"00{number}", f"0x{number:x}", f"0X{number:04X}",
    ])


@given(st.integers(1, 0xFFFF).flatmap(lambda n: st.tuples(st.just(n), spellings(n))))
def test_any_uns16_spelling_parses_to_itself(case: tuple[int, str]) -> None:
    number, text = case
    assert parse_axis_list(f"kopf.achs_nr {text}", "a") == {"logical_number": number}


@given(st.integers(-(2**31), 2**31 - 1))
def test_any_sgn32_parses_to_tenths_of_micrometres(number: int) -> None:
    result = parse_axis_list(f"kopf.achs_nr 1\nkenngr.swe_neg {number}", "a")
    assert result["limits"]["sw_limit_min_mm"] == number / 10_000


KEYS = ["kopf.achs_nr", "kopf.clone_of", "kenngr.achs_typ", "getriebe[0].dynamik.vb_max",
        "getriebe[1].dynamik.a_max", "gruppe[0].achs_anzahl", "gruppe[0].achse[0].bezeichnung",
        "gruppe[0].achse[1].log_achs_nr", "jog_of_path_only", "x[", "#", "", "GRUPPE[0]"]
VALUES = ["", "0", "1", "2", "4", "X", "x1", "0x10", "-5", "ACHSTYP_SPINDEL", "# c", "1 2"]


@given(st.lists(st.tuples(st.sampled_from(KEYS), st.sampled_from(VALUES)), max_size=12),
       st.sampled_from([parse_axis_list, parse_channel_list]))
def test_any_list_is_parsed_or_refused_with_problems_in_it(lines, parse) -> None:
    text = "\n".join(f"{key} {value}" for key, value in lines)
    try:
        result = parse(text, "p.lis")
    except ParamListError as error:
        assert error.problems
        assert all(p.file == "p.lis" and 0 <= p.line <= len(lines) for p in error.problems)
    else:
        assert isinstance(result, dict)
