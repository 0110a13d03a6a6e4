"""The output area and its writer thread: appends append, limits name their key, a log
keeps its newest lines, a download waits only for its own file's queued writes."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from cnc_objects.service.kernel.nc.technology import OutputLimitReached
from cnc_objects.service.storage.output_area import OutputArea
from cnc_objects.service.storage.output_writer import OutputLimits, OutputWriter

LIMITS = OutputLimits(max_files=3, max_file_bytes=4096, max_total_bytes=10_000,
                      queue_max_bytes=1 << 20)


@pytest.fixture
def writer(tmp_path: Path) -> Iterator[OutputWriter]:
    w = OutputWriter(OutputArea(tmp_path / "output"), LIMITS)
    yield w
    w.close()


def written(w: OutputWriter, name: str) -> bytes:
    """The file once the writes queued for it are on disk."""
    done = threading.Event()
    if w.when_written(name, done.set):
        assert done.wait(5), f"{name} was not written within 5 s"
    return w.area.read(name)


def hold_the_writer(w: OutputWriter) -> threading.Event:
    """Keep the writer thread busy making ``first.csv`` until the returned event is set."""
    busy, gate = threading.Event(), threading.Event()

    def make() -> bytes:
        busy.set()
        gate.wait(5)
        return b"1"

    w.kernel_file("first.csv", make, replace=True)
    assert busy.wait(5)
    return gate


def test_appends_append_and_exclusive_replaces_once(writer) -> None:
    writer.save("m.txt", b"one\n")
    writer.save("m.txt", b"two\n")
    assert written(writer, "m.txt") == b"one\ntwo\n"
    inode = (writer.area.root / "m.txt").stat().st_ino
    writer.save("m.txt", b"three\n")
    assert written(writer, "m.txt") == b"one\ntwo\nthree\n"
    assert (writer.area.root / "m.txt").stat().st_ino == inode  # appended, not rewritten
    writer.save("m.txt", b"new\n", replace=True)
    assert written(writer, "m.txt") == b"new\n"


@pytest.mark.parametrize(("writes", "limit"), [
    ([("a", 4000), ("a", 100)], "output_max_file_bytes"),
    ([("a", 10), ("b", 10), ("c", 10), ("d", 10)], "output_max_files"),
    ([("a", 4000), ("b", 4000), ("c", 2100)], "output_max_total_bytes"),
])
def test_a_write_over_a_limit_is_refused_naming_the_key(writer, writes, limit) -> None:
    *fine, (name, size) = writes
    for n, s in fine:
        writer.save(n, b"x" * s)
    before = [(p.name, p.size_bytes) for p in writer.listing()]
    with pytest.raises(OutputLimitReached) as refused:
        writer.save(name, b"x" * size)
    assert refused.value.limit == limit and f"[limits] {limit} = " in str(refused.value)
    assert [(p.name, p.size_bytes) for p in writer.listing()] == before


def test_a_full_queue_refuses_an_nc_write_and_drops_a_log_line(tmp_path) -> None:
    w = OutputWriter(OutputArea(tmp_path), OutputLimits(queue_max_bytes=1 << 20))
    gate = hold_the_writer(w)
    w.kernel_file("prodtime01.csv", lambda: b"made\n", replace=True)  # counts as 1 MB queued
    with pytest.raises(OutputLimitReached) as refused:
        w.save("a", b"x" * 50_000)
    assert refused.value.limit == "output_queue_max_bytes"
    w.kernel_file("errors-ch1.log", b"y" * 50_000 + b"\n")
    assert w.dropped.count == 1
    gate.set()
    w.close()
    assert w.area.read("prodtime01.csv") == b"made\n"
    assert [p.name for p in w.area.list()] == ["first.csv", "prodtime01.csv"]


def test_a_log_keeps_its_newest_lines_cut_once_per_half_limit(writer) -> None:
    line = b"%04d" + b"-" * 95 + b"\n"  # 100 bytes
    inodes = set()
    for k in range(200):
        writer.kernel_file("errors-ch1.log", line % k)
        if k % 10 == 9:
            written(writer, "errors-ch1.log")
            inodes.add((writer.area.root / "errors-ch1.log").stat().st_ino)
    content = written(writer, "errors-ch1.log")
    assert len(content) <= LIMITS.max_file_bytes
    assert content.endswith(line % 199) and content.startswith(b"0")  # whole lines
    assert len(inodes) <= 200 * 100 // (LIMITS.max_file_bytes // 2) + 1  # few rewrites


def test_a_newer_report_supersedes_one_still_queued(tmp_path) -> None:
    w = OutputWriter(OutputArea(tmp_path))
    gate = hold_the_writer(w)
    w.kernel_file("dec01.sc", b"old", replace=True)
    w.kernel_file("dec01.sc", b"new", replace=True)
    gate.set()
    w.close()
    assert w.area.read("dec01.sc") == b"new"


def test_delete_is_ordered_after_queued_writes_and_frees_room(writer) -> None:
    writer.save("a", b"x" * 4000)
    assert writer.delete("a")
    assert not writer.delete("a")
    writer.save("b", b"y" * 4000)
    assert written(writer, "b") == b"y" * 4000
    assert [p.name for p in writer.listing()] == ["b"]
    assert not (writer.area.root / "a").exists()


def test_close_writes_everything_queued_and_refuses_more(tmp_path) -> None:
    w = OutputWriter(OutputArea(tmp_path))
    for k in range(1000):
        w.save("m.txt", b"%d padding-padding\n" % k)
    w.close()
    lines = w.area.read("m.txt").splitlines()
    assert lines == [b"%d padding-padding" % k for k in range(1000)]
    with pytest.raises(ValueError, match="stopping"):
        w.save("m.txt", b"late\n")


def test_bad_names_are_refused(writer) -> None:
    for name in ("../x", "a/b", ".hidden", ""):
        with pytest.raises(ValueError, match="output file name"):
            writer.save(name, b"x")
