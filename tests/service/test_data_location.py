"""Where a service's program store is: options over configuration, store over data dir;
and its output area, never the store."""

from __future__ import annotations

from pathlib import Path

import pytest

from cnc_objects.service.storage.data_location import output_area_location, program_store_location


@pytest.mark.parametrize(
    ("program_dir", "data_dir", "key_program_dir", "key_data_dir", "store", "source"),
    [
        (None, None, None, None, "cnc-data/programs",
         "default: cnc-data/programs in the working directory"),
        (None, None, None, "data", "data/programs", "data_dir of the configuration"),
        (None, None, "progs", "data", "progs", "program_store_dir of the configuration"),
        (None, "d", "progs", "data", "d/programs", "--data-dir"),
        ("p", "d", "progs", "data", "p", "--program-dir"),
        (None, None, "", "", "cnc-data/programs",
         "default: cnc-data/programs in the working directory"),
    ],
)
def test_the_first_given_decides(
    tmp_path: Path, program_dir: str | None, data_dir: str | None, key_program_dir: str | None,
    key_data_dir: str | None, store: str, source: str,
) -> None:
    location = program_store_location(
        Path(program_dir) if program_dir else None, Path(data_dir) if data_dir else None,
        key_program_dir, key_data_dir, cwd=tmp_path,
    )
    assert location.path == (tmp_path / store).resolve()
    assert location.source == source


def test_paths_are_absolute_with_home_expanded(tmp_path: Path) -> None:
    assert program_store_location(None, Path("~/cnc"), None, None, tmp_path).path == (
        Path.home() / "cnc" / "programs").resolve()
    assert program_store_location(None, None, None, str(tmp_path / "abs"), Path("/")).path == (
        tmp_path / "abs" / "programs").resolve()
    assert program_store_location(None, None, None, "a/../b", tmp_path).path == (
        tmp_path.resolve() / "b" / "programs")


@pytest.mark.parametrize(
    ("program_dir", "data_dir", "output_dir", "key_output_dir", "output", "source"),
    [
        (None, None, None, None, "cnc-data/output", "output/ in the data directory"),
        (None, "d", None, None, "d/output", "output/ in the data directory"),
        ("data/progs", None, None, None, "data/progs-output", "beside the program store"),
        ("p", None, None, "outs", "outs", "output_dir of the configuration"),
        ("p", None, "o", "outs", "o", "--output-dir"),
    ],
)
def test_the_output_area_is_a_directory_of_its_own(
    tmp_path: Path, program_dir: str | None, data_dir: str | None, output_dir: str | None,
    key_output_dir: str | None, output: str, source: str,
) -> None:
    store = program_store_location(Path(program_dir) if program_dir else None,
                                   Path(data_dir) if data_dir else None, None, None, tmp_path)
    location = output_area_location(Path(output_dir) if output_dir else None,
                                    key_output_dir, store, cwd=tmp_path)
    assert location.path == (tmp_path / output).resolve()
    assert location.source == source


@pytest.mark.parametrize("output_dir", ["p", "p/sub", "."])
def test_an_output_area_in_or_around_the_store_is_refused(tmp_path: Path, output_dir: str) -> None:
    store = program_store_location(Path("p"), None, None, None, tmp_path)
    with pytest.raises(ValueError, match="must not be the program store"):
        output_area_location(Path(output_dir), None, store, cwd=tmp_path)
