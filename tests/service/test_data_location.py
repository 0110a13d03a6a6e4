"""Where a service's program store is: options over configuration, store over data dir."""

from __future__ import annotations

from pathlib import Path

import pytest

from cnc_objects.service.data_location import program_store_location


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
