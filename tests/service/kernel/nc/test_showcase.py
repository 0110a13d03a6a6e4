"""The ISG syntax showcase (vscode-isg-cnc test file): real errors, never a crash.

Decoding starts at the main program ``%MAIN`` (line 19): the local subprograms UP1 and
UP2 before it, with their broken ``N0 N1.....`` lines, only run when called. The first
line of the main program calls ``L subPrograms.nc`` with continuation lines; its
third physical line holds ``G33`` (thread cutting), which this decoder does not
support: that is the first real error, at line 22 column 3, whatever the program store
holds (the block is parsed before its call runs).
"""

from __future__ import annotations

from itertools import islice
from pathlib import Path

import pytest

from cnc_objects.service.kernel.nc import NcError, NcErrorId

from .support import decoder

SHOWCASE = Path(__file__).resolve().parents[3] / "data" / "isg-syntax-showcase.nc"
TEXT = SHOWCASE.read_text(encoding="utf-8")


@pytest.mark.parametrize("files", [{}, {"subPrograms.nc": "G0 X1\nM17\n"}])
def test_first_real_error(files) -> None:
    d = decoder(TEXT, files=files, file="isg-syntax-showcase.nc")
    with pytest.raises(NcError) as info:
        list(d.blocks())
    e = info.value
    assert (e.id, e.file, e.line, e.column) == (
        NcErrorId.UNSUPPORTED_G_CODE, "isg-syntax-showcase.nc", 22, 3)
    assert e.message == "G33 is not supported"


@pytest.mark.parametrize("skip_levels", [0, 1])
@pytest.mark.parametrize("manual", [False, True])
def test_every_line_alone_gives_blocks_or_an_nc_error(skip_levels, manual) -> None:
    lines = TEXT.split("\n")
    for number, line in enumerate(lines, start=1):
        for text in (line, "\n".join(lines[number - 1:])):
            d = decoder(text, manual=manual, skip_levels=skip_levels)
            try:
                list(islice(d.blocks(), 200))
            except NcError as e:
                assert e.id != NcErrorId.INTERNAL_ERROR, str(e)


def test_syntax_check_reports_every_parse_error_and_goes_through() -> None:
    from cnc_objects.service.kernel.nc import check_syntax

    errors = check_syntax(TEXT, "s.nc", axes=("X", "Y", "Z"))
    found = [(e.line, e.column, e.id) for e in errors]
    assert (5, 4, NcErrorId.BLOCK_NUMBER_TWICE) in found  # N0 N1..... in %L UP1
    assert (22, 3, NcErrorId.UNSUPPORTED_G_CODE) in found  # G33 in a continuation line
    # LL CYCLE [...] over 24 lines (commented-out parameters inside) is a valid call
    assert not [e for e in errors if 82 <= e.line <= 105]
    assert (109, 1, NcErrorId.UNKNOWN_WORD) in found  # awigaiw
    assert (128, 5, NcErrorId.UNKNOWN_WORD) in found  # A0: no A axis
    assert found == sorted(found)
    assert all(e.id != NcErrorId.INTERNAL_ERROR for e in errors)
    # the #VAR block (typed declarations, a list over two lines) is valid
    assert not [e for e in errors if 49 <= e.line <= 64]


def test_syntax_check_of_a_clean_program() -> None:
    from cnc_objects.service.kernel.nc import check_syntax

    program = "%P\n#VAR\nV.L.A[2] = [1,\n 2]\n#ENDVAR\nG1 X[V.L.A[0]] F100\nLL S\nM30\n%L S\nM17\n"
    assert check_syntax(program, "p.nc", axes=("X", "Y", "Z")) == []
