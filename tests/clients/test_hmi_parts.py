"""The HMI's operator parts that need no service: the program panel's window of lines,
the MDI history's recall and file, the connection line's text."""

from __future__ import annotations

import time
from pathlib import Path

from cnc_objects.clients.hmi.connection_state import no_reply_text
from cnc_objects.clients.hmi.mdi import HISTORY_MAX, MdiHistory, blocks
from cnc_objects.clients.hmi.program_view import WINDOW_LINES, window


def test_window_keeps_the_current_line_in_the_middle_and_inside_the_text() -> None:
    assert list(window(20, 10)) == list(range(6, 15))  # 4 above, 4 below
    assert list(window(20, 1)) == list(range(1, 10))  # at the start: moved down
    assert list(window(20, 20)) == list(range(12, 21))  # at the end: moved up
    assert list(window(3, 0)) == [1, 2, 3]  # no line in execution: the start
    assert list(window(0, 0)) == []
    assert all(len(window(n, c)) == min(n, WINDOW_LINES) for n in range(30) for c in range(n))


def test_mdi_history_recalls_keeps_a_draft_and_survives_in_its_file(tmp_path: Path) -> None:
    file = tmp_path / "deep" / "mdi-history"
    history = MdiHistory(file)
    assert history.older("G0") == "G0" and history.newer() == "G0"  # empty: the draft
    for line in ("G1 X1", "G1 X2", "G1 X2", "  "):  # a repeat and a blank line: not kept
        history.add(line)
    assert history.entries == ["G1 X1", "G1 X2"]
    assert [history.older("typed"), history.older("x"), history.older("x")] == [
        "G1 X2", "G1 X1", "G1 X1"]
    assert [history.newer(), history.newer(), history.newer()] == ["G1 X2", "typed", "typed"]
    assert MdiHistory(file).entries == ["G1 X1", "G1 X2"]
    for k in range(HISTORY_MAX + 5):
        history.add(f"G1 X{k}")
    assert MdiHistory(file).entries[0] == "G1 X5" and len(MdiHistory(file).entries) == HISTORY_MAX
    assert MdiHistory(None).entries == []  # no file: the session only
    assert blocks(r"G1 X1\nG1 Y2") == "G1 X1\nG1 Y2"


def test_mdi_history_in_a_place_it_cannot_write_keeps_the_session(tmp_path: Path) -> None:
    blocked = tmp_path / "a-file"
    blocked.write_text("not a directory")
    history = MdiHistory(blocked / "mdi-history")  # its directory cannot be made
    history.add("G1 X1")
    assert history.entries == ["G1 X1"] and history.older("") == "G1 X1"


def test_no_reply_text_says_since_when_in_local_time() -> None:
    last = time.mktime((2026, 11, 27, 10, 42, 13, 0, 0, -1))
    assert no_reply_text("tcp://h:5555", last, last + 12.7) == (
        "no reply from tcp://h:5555 since 10:42:13 (12 s) — values greyed, retrying")
    assert "(0 s)" in no_reply_text("tcp://h:5555", last, last - 1)  # a clock step back
