"""The program store: name rules, size bound, atomic replace, listing, faults."""

from __future__ import annotations

import threading

import pytest

from cnc_objects.service.storage.program_store import ProgramStore, StoreError, StoreFault, check_name


@pytest.fixture
def store(tmp_path):
    return ProgramStore(tmp_path / "programs", max_bytes=1000, max_files=3)


@pytest.mark.parametrize(
    "name", ["a.nc", "part_01.nc", "L-sub.nc", "X", "9.nc", "a" * 83]
)
def test_plain_names_are_accepted(name) -> None:
    assert check_name(name) == name


@pytest.mark.parametrize(
    "name",
    ["", "../x.nc", "a/b.nc", "a\\b.nc", "..", "x..nc", ".hidden", "a b.nc", "a" * 84,
     "ä.nc", "a\x00b"],
)
def test_bad_names_are_refused(name) -> None:
    with pytest.raises(StoreError) as info:
        check_name(name)
    assert info.value.fault == StoreFault.BAD_NAME


def test_write_read_list_delete(store) -> None:
    store.write("b.nc", b"G1 X1 F100\nM30\n")
    store.write("a.nc", b"M30\n")
    assert [(p.name, p.size_bytes) for p in store.list()] == [("a.nc", 4), ("b.nc", 15)]
    assert store.read("b.nc") == b"G1 X1 F100\nM30\n"
    assert store.exists("a.nc") and not store.exists("c.nc") and not store.exists("../a.nc")
    store.delete("a.nc")
    assert [p.name for p in store.list()] == ["b.nc"]


def test_replace_is_whole(store) -> None:
    store.write("a.nc", b"old")
    store.write("a.nc", b"new content")
    assert store.read("a.nc") == b"new content"
    assert [p.name for p in store.list()] == ["a.nc"]  # no temporary file left behind


def test_oversized_upload_changes_nothing(store) -> None:
    store.write("a.nc", b"keep")
    with pytest.raises(StoreError) as info:
        store.write("a.nc", b"x" * 1001)
    assert info.value.fault == StoreFault.TOO_LARGE
    assert store.read("a.nc") == b"keep"


def test_full_store_refuses_new_names_but_replaces_old(store) -> None:
    for n in "abc":
        store.write(f"{n}.nc", b"M30\n")
    with pytest.raises(StoreError) as info:
        store.write("d.nc", b"M30\n")
    assert info.value.fault == StoreFault.FULL
    store.write("a.nc", b"G0 X1\nM30\n")  # replacing is not a new file
    assert store.read("a.nc") == b"G0 X1\nM30\n"


def test_missing_program(store) -> None:
    for op in (store.read, store.delete):
        with pytest.raises(StoreError) as info:
            op("nope.nc")
        assert info.value.fault == StoreFault.NOT_FOUND
        assert "nope.nc" in str(info.value)


def test_text_falls_back_to_cp1252(store) -> None:
    store.write("umlaut.nc", "( Übergang )\nM30\n".encode("cp1252"))
    assert store.read_text("umlaut.nc").startswith("( Übergang )")


def test_a_reader_never_sees_half_a_file(store) -> None:
    """A writer replaces a file over and over; a reader only ever sees a whole version."""
    versions = [bytes([65 + k]) * 900 for k in range(5)]
    store.write("p.nc", versions[0])
    done = threading.Event()

    def writer() -> None:
        for k in range(200):
            store.write("p.nc", versions[k % 5])
        done.set()

    t = threading.Thread(target=writer)
    t.start()
    seen = 0
    while not done.is_set():
        assert store.read("p.nc") in versions
        seen += 1
    t.join()
    assert seen > 0


def test_the_store_has_no_path_for_kernel_writes(store) -> None:
    """Only upload and delete change the store: the files the kernel writes go to the
    output area (service/storage/output_writer.py), so the store offers no append to reach
    (a chunked upload appends to its own temporary file, ``program_uploads``)."""
    assert [name for name in dir(store) if not name.startswith("_")] == [
        "delete", "exists", "list", "max_bytes", "max_files", "max_total_bytes", "path_of", "read",
        "read_text", "remove_unfinished_uploads", "replace_with", "root", "size_bytes",
        "used_bytes", "write"]
