"""Long lines: the parser, the syntax check's repositioning and the executor take time
linear in a line's length, and the check's one-pass repositioning gives what blanking
the bad term and parsing the line again (the reference) gives.

Times are this process' CPU time, the cheapest of three runs: the ratio for 4x the words
must stay under 8 (linear: about 4; the quadratic code of issue 25 gave 16).
"""

from __future__ import annotations

import gc
import time
from collections.abc import Callable

import pytest

from cnc_objects.service.kernel.nc import Decoder, NcError
from cnc_objects.service.kernel.nc.check import (
    EXACT_REPOSITIONS,
    ErrorCategory,
    RepositionedLine,
    categorize,
    parse_checked,
    term_end,
    term_start,
    without_error,
)
from cnc_objects.service.kernel.nc.parser import LineParser, word_table
from cnc_objects.service.kernel.nc.source import LogicalLine
from tests.support.check_mode import Recorder

from .support import AXES, TOOLS, loader_of

RATIO_MAX = 8.0


class Counter(Recorder):
    """A recorder that keeps (id, column, category) of each error, as the kernel keeps
    errors: without their tracebacks (which hold the parser's frames; kept by the
    thousand they make the garbage collector's work grow with the count)."""

    def __init__(self) -> None:
        super().__init__()
        self.seen: list[tuple[int, int, ErrorCategory]] = []

    def report(self, error: NcError, category: ErrorCategory) -> None:
        self.seen.append((int(error.id), error.column, category))


def cpu_cost_s(work: Callable[[], object]) -> float:
    """The cheapest of three runs of ``work``, in CPU seconds of this process, with the
    garbage collector held off during each (a collection that happens to fall into the
    large run made the ratio jump on a loaded machine; the algorithm is what is measured)."""
    costs = []
    for _ in range(3):
        gc.collect()
        gc.disable()
        try:
            start = time.process_time()
            work()
            costs.append(time.process_time() - start)
        finally:
            gc.enable()
    return min(costs)


def assert_linear(make: Callable[[int], Callable[[], object]], small: int) -> None:
    """``make(n)`` costs about 4 times as much for 4n as for n."""
    small_s = cpu_cost_s(make(small))
    large_s = cpu_cost_s(make(4 * small))
    ratio = large_s / max(small_s, 1e-3)
    assert ratio < RATIO_MAX, f"n={small}: {small_s:.3f} s, 4n: {large_s:.3f} s (x{ratio:.1f})"


def logical(text: str) -> LogicalLine:
    return LogicalLine("p.nc", text, ((0, 0, 0),), 0)


PARSER = LineParser(word_table(AXES))


def reference_parse_checked(line: LogicalLine, check: Recorder):
    """The check's repositioning as it was: blank the bad term, parse again from the
    start (quadratic, but the reference for what one pass must give)."""
    while True:
        try:
            return PARSER.parse(line)
        except NcError as error:
            category = categorize(error, line)
            check.report(error, category)
            again = without_error(line, error, category)
            if again is None or again.text == line.text:
                return None
            line = again


def items_of(stmt) -> list[tuple[str, object, int]]:
    if stmt is None:
        return []
    return [(getattr(i, "letter", "="), getattr(i, "value", None) if not callable(
        getattr(i, "value", None)) else "expr", i.pos) for i in stmt.items]


@pytest.mark.parametrize("text", [
    "N1 G01 X1 F100 X1 X1 X2",  # a word twice
    "Q5 X1 Q6 Y2 QQ Z3",  # unknown words
    "X[1+] Y2 Z[",  # bad brackets, an unclosed one at the end
    "N1 N2 X1 N3 Y1",  # block number twice
    "G1 X1.2.3 Y1",  # a malformed number
    "V.P.A = 1 +* 2 X1 V.P.B = * Y2",  # errors inside an assignment's expression
    "X Y2 Z",  # missing values
    "G1 G133 = X1 F",  # a weighting without its value, F without one
])
def test_one_pass_repositioning_gives_what_parsing_again_gives(text: str) -> None:
    one_pass, reference = Recorder(), Recorder()
    got = parse_checked(PARSER.parse, logical(text), one_pass)
    want = reference_parse_checked(logical(text), reference)
    assert [(int(e.id), e.column, c) for e, c in one_pass.errors] == \
        [(int(e.id), e.column, c) for e, c in reference.errors]
    assert items_of(got) == items_of(want)
    if one_pass.errors:
        assert got is None or got.line.errors == len(one_pass.errors)


def test_errors_inside_terms_beyond_the_copies_drop_the_whole_term() -> None:
    """After ``EXACT_REPOSITIONS`` blanked copies in one line, an error inside a term
    drops the term; every error is still reported once, and the check goes on."""
    count = EXACT_REPOSITIONS + 10
    check = Recorder()
    stmt = parse_checked(PARSER.parse, logical("G1 " + "M[1+*2] " * count + "X5"), check)
    assert len(check.errors) == count
    assert [i.letter for i in stmt.items][-1] == "X"


def test_repositioned_line_shares_the_text_of_its_line() -> None:
    line = logical("X1 " * 10)
    counted = RepositionedLine.counted(line, 3)
    assert counted.text is line.text and counted.upper is line.upper and counted.errors == 3


@pytest.mark.parametrize("text, pos, start", [
    ("X1 Y[1+ 2] Z3", 8, 3), ("X1 Y2", 3, 3), ('X1 M["a b" Y2', 9, 3), ("X1 Y[1", 6, 3),
])
def test_term_start_from_the_item_is_term_start_from_the_line(text, pos, start) -> None:
    assert term_start(text, pos) == start
    assert term_start(text, pos, 3) == start


@pytest.mark.parametrize("text, pos, end", [
    ("X1 Y2", 0, 2), ("X[1 + 2] Y2", 0, 8), ('M["a b"] Y', 0, 8), (" X1", 0, 3), ("X[1", 0, 3),
])
def test_term_end(text, pos, end) -> None:
    assert term_end(text, pos) == end


def test_term_functions_are_linear() -> None:
    def make(n: int):
        text = "X1 " * n
        return lambda: [term_end(text, term_start(text, k, k)) for k in range(0, 3 * n, 3)]
    assert_linear(make, 20_000)


def test_parse_checked_is_linear_in_the_bad_words_of_a_line() -> None:
    def make(n: int):
        line = logical("N1 G01 X1 F100 " + "X1 " * n)
        return lambda: parse_checked(PARSER.parse, line, Counter())
    assert_linear(make, 5_000)


def test_parse_checked_is_linear_in_errors_inside_terms() -> None:
    def make(n: int):
        line = logical("G1 " + "M[1+*2] " * n)
        return lambda: parse_checked(PARSER.parse, line, Counter())
    assert_linear(make, 3_000)


def test_the_parser_is_linear_in_the_words_of_a_valid_line() -> None:
    def make(n: int):
        line = logical("G1 X1 F100 " + " ".join(f"M{100 + k}" for k in range(n)))
        return lambda: PARSER.parse(line)
    assert_linear(make, 5_000)


def _check_decode(text: str) -> Callable[[], object]:
    def run() -> int:
        decoder = Decoder(text, "p.nc", axes=AXES, loader=loader_of({}), tools=TOOLS,
                          check=Counter())
        return sum(1 for _ in decoder.blocks())
    return run


def _decode(text: str) -> Callable[[], object]:
    def run() -> int:
        decoder = Decoder(text, "p.nc", axes=AXES, loader=loader_of({}), tools=TOOLS)
        return sum(1 for _ in decoder.blocks())
    return run


@pytest.mark.parametrize("words", [
    "X1 ",  # a parse error per word
    "G0 G1 ",  # an execution error per word (G of one group twice)
    "M[1/0] ",  # an evaluation error per word
    "M30 ",  # a second program-flow M per word
])
def test_the_check_of_a_line_is_linear_in_its_errors(words: str) -> None:
    assert_linear(lambda n: _check_decode("N1 G01 X1 F100 " + words * n + "\nM30\n"), 4_000)


def test_the_check_reports_each_error_of_a_long_line_once() -> None:
    check = Recorder()
    n = 3_000
    decoder = Decoder("N1 G01 X1 F100 " + "G0 G1 " * n + "M[1/0] " * n + "\nM30\n", "p.nc",
                      axes=AXES, loader=loader_of({}), tools=TOOLS, check=check)
    blocks = list(decoder.blocks())
    assert len(check.errors) == 3 * n
    assert {c for _, c in check.errors} == {ErrorCategory.COMBINATION, ErrorCategory.VALUE}
    assert blocks[-1].stop.name == "PROGRAM_END"


@pytest.mark.parametrize("line", [
    lambda n: "N1 G01 X1 F100 " + " ".join(f"M{100 + k}" for k in range(n)),
    lambda n: "N1 G01 F100 X[1" + "+1-1" * n + "]",
    lambda n: "N1 G01 X1 F100 (" + "c" * (4 * n) + ")",
    lambda n: "N1 G01 X1 F100 ;" + "c" * (4 * n),
], ids=["distinct words", "long expression", "long comment", "long ; comment"])
def test_decoding_a_valid_line_is_linear(line) -> None:
    assert_linear(lambda n: _decode(line(n) + "\nM30\n"), 5_000)
