"""A program read from its file page by page decodes exactly as its text held whole.

The store's programs reach the decoder as files (``text_pages``): pages of lines are read
as decoding goes. Small pages (a few bytes: every line on a page of its own, comment
blocks, continuations and loops across pages) must give the same lines, byte offsets,
sections, blocks and errors (id, file, line, column) as the text in memory; and the
memory a decoder holds does not grow with the program.
"""

from __future__ import annotations

import tracemalloc
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cnc_objects.service.kernel.nc import Decoder, NcError, text_pages
from cnc_objects.service.kernel.nc.text_pages import SourceText
from tests.support.cam_programs import write_cam_program

from .support import AXES, TOOLS

PAGE_SIZES = (1, 5, 16, 64, 4096)

PROGRAMS = {
    "labels": "N10 G90 G1 F1000 X1\n$GOTO N30\nN20: X2\n$GOTO [END]\nN30: X3\n"
              "$GOTO N20\n[END] Y4\nM30\n",
    "loops": "#VAR\nV.L.I = 0\n#ENDVAR\nG1 F600\n$WHILE V.L.I < 4\nX[V.L.I] Y1\n"
             "$IF V.L.I == 2\nZ1\n$ELSE\nZ0\n$ENDIF\nV.L.I = V.L.I + 1\n$ENDWHILE\nM30\n",
    "sections": "; locals before and after the main program\n%L UP1   (first)\nG0 X1\nM17\n"
                "%L UP2\nG0 X2\n%MAIN\nLL UP1\nLL UP2\nL sub.nc\nLL UP3\nM30\n%L UP3\n"
                "G0 X3\nM29\n",
    "comments": "#COMMENT BEGIN\nQ5 anything\n%L NOT_A_SECTION\n#COMMENT END\n"
                "G0 X1 (a comment) Y2 ; more\n/ G0 X9\nL CYCLE [NAME=none \\\n"
                "; a parameter commented out\n  @P1=2 ]\nM30\n",
    "crlf_and_bom": "\ufeffN1 G90 G1 F500 X1\r\nN2 Y2 ; ä in a comment\r\nN3 Z3\r\nM30\r\n",
    "error_at_the_end": "G1 F100 X1\n" * 40 + "G1 X2 Q7\nM30\n",
    "error_in_a_continuation": "G1 F100 X1\nG1 X2 \\\n  Y3 \\\n  Q4\nM30\n",
    "no_program_end": "G0 X1\n\n; trailing comment\n",
    "goto_backwards_far": "#VAR\nV.L.N = 0\n#ENDVAR\nN1 G1 F900\n[BACK] X0\n"
                          + "".join(f"X{k} Y{k % 7}\n" for k in range(1, 60))
                          + "V.L.N = V.L.N + 1\n$IF V.L.N < 3 $GOTO [BACK]\nM30\n",
}
SUB = "%SUB\nG0 Z9\nLL INNER\nM17\n%L INNER\nG0 Y7\nM17\n"


def decode_all(text, tmp_path: Path | None) -> tuple[list, tuple | None]:
    """Blocks and the error (id, file, line, column, message) of ``text``: held whole
    (``tmp_path`` None) or written to a file and read as a stream."""
    source: str | Path = text
    files: dict[str, str | Path] = {"sub.nc": SUB}
    if tmp_path is not None:
        source = tmp_path / "prog.nc"
        source.write_bytes(text.encode("utf-8"))
        (tmp_path / "sub.nc").write_text(SUB)
        files = {"sub.nc": tmp_path / "sub.nc"}
    decoder = Decoder(source, "prog.nc", axes=AXES, loader=files.__getitem__, tools=TOOLS)
    blocks = []
    error = None
    try:
        for block in decoder.blocks():
            blocks.append(block)
    except NcError as exc:
        error = (exc.id, exc.file, exc.line, exc.column, exc.message)
    finally:
        decoder.close()
    return blocks, error


@pytest.mark.parametrize("page_bytes", PAGE_SIZES)
@pytest.mark.parametrize("name", sorted(PROGRAMS))
def test_a_program_read_in_pages_decodes_as_the_text_held_whole(
    name: str, page_bytes: int, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(text_pages, "PAGE_BYTES", page_bytes)
    monkeypatch.setattr(text_pages, "PAGES_KEPT", 2)  # loops and jumps leave the pages kept
    whole = decode_all(PROGRAMS[name], None)
    streamed = decode_all(PROGRAMS[name], tmp_path)
    assert streamed == whole
    assert whole[0] or whole[1]  # the program decodes to something


LINE_TEXT = st.text(alphabet=st.sampled_from("G1 X.5%#;()\r\\äÿ€COMENTBGI"), max_size=12)


@settings(max_examples=150, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(lines=st.lists(LINE_TEXT, max_size=30), page_bytes=st.integers(1, 40),
       bom=st.booleans(), cp1252=st.booleans())
def test_lines_offsets_and_sections_of_a_file_match_its_text(
    tmp_path: Path, lines: list[str], page_bytes: int, bom: bool, cp1252: bool
) -> None:
    text = "\n".join(lines)
    data = text.encode("cp1252" if cp1252 else "utf-8")
    if bom:
        data = b"\xef\xbb\xbf" + data
    path = tmp_path / "p.nc"
    path.write_bytes(data)
    streamed = SourceText.open(path, "p.nc", page_bytes=page_bytes)
    try:
        # what the store's read_text gives the kernel when held whole (a byte order
        # mark is 3 bytes before the first line, whatever the encoding of the rest)
        body = data[3:] if bom else data
        try:
            decoded = body.decode("utf-8")
        except UnicodeDecodeError:
            decoded = body.decode("cp1252", errors="replace")
        decoded = "\ufeff" + decoded if bom else decoded
        whole = SourceText(decoded, "p.nc")
        assert streamed.count == whole.count
        order = list(range(whole.count))
        for k in order + order[::-1]:  # forwards, then backwards across the pages
            assert streamed.line(k) == whole.line(k)
            if not cp1252 or text.isascii():  # CP1252: byte offsets of the file itself
                assert streamed.offset(k) == whole.offset(k)
        last_line = body.rsplit(b"\n", 1)[-1]
        assert streamed.offset(whole.count - 1) + len(last_line) == len(data)
        assert streamed.marked_lines() == whole.marked_lines()
    finally:
        streamed.close()


def decoding_peak_bytes(path: Path, blocks_wanted: int) -> int:
    """Peak Python memory of opening ``path`` and decoding ``blocks_wanted`` blocks."""
    tracemalloc.start()
    try:
        decoder = Decoder(path, path.name, axes=AXES, loader=lambda name: path, tools=TOOLS)
        taken = 0
        for _ in decoder.blocks():
            taken += 1
            if taken >= blocks_wanted:
                break
        decoder.close()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_the_memory_of_a_decoder_does_not_grow_with_the_program(tmp_path: Path) -> None:
    small, large = tmp_path / "small.nc", tmp_path / "large.nc"
    write_cam_program(small, 4_000_000)
    write_cam_program(large, 20_000_000)
    # past the first pages of both, so the reading of pages is part of it
    small_peak = decoding_peak_bytes(small, 30_000)
    large_peak = decoding_peak_bytes(large, 30_000)
    # the page index grows (a few bytes per 128 KiB page), the lines held do not
    assert large_peak < small_peak + 1_000_000, (small_peak, large_peak)
    assert large_peak < 10_000_000  # not the 20 MB of text (held whole: ~80 MB of lines)
