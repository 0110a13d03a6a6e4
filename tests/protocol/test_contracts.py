"""Contracts both sides use, written once in protocol: what one side writes, the other
reads back as it was meant."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from cnc_objects.clients.channel_ops import parse_check_log
from cnc_objects.protocol import check_log
from cnc_objects.protocol.file_listing import decode_listing, encode_listing

_NAMES = st.from_regex(r"[A-Za-z0-9_][A-Za-z0-9_.\-]{0,40}", fullmatch=True)


@given(st.lists(st.tuples(_NAMES, st.integers(0, 10**9),
                          st.integers(0, 4 * 10**9).map(lambda ms: ms / 1000))))
def test_a_listing_decodes_to_what_was_encoded(files: list[tuple[str, int, float]]) -> None:
    assert decode_listing(encode_listing(files)) == files


def test_a_check_log_written_with_the_contract_parses_back() -> None:
    text = "\n".join([
        check_log.header_line("we:ird.nc", 2),
        "we:ird.nc:3: G01 X10 Y5",
        check_log.error_line(21220, "syntax", "we:ird.nc", 4, 8, "unknown word 'Q7'"),
        check_log.left_out_line(12, "limits.check_max_errors: the first 1 are kept"),
        check_log.end_line(12, 9, 13, f"{check_log.STOPPED}: syn_chk.errors_total reached"),
    ]) + "\n"
    result = parse_check_log(text)
    assert [(e.file, e.line, e.column, e.id, e.category) for e in result.errors] == [
        ("we:ird.nc", 4, 8, 21220, "syntax")]
    assert (result.left_out, result.error_count, result.stopped_early) == (12, 13, True)
    assert check_log.check_log_name(2) == "dec02.sc"
