"""Where a service keeps its data: the program store's directory, the output area's, and
why there.

Each service has a store of its own. The first of these that is given decides:

1. ``--program-dir DIR``: the store itself;
2. ``--data-dir DIR``: the store is ``DIR/programs``;
3. ``program_store_dir`` of the configuration: the store itself;
4. ``data_dir`` of the configuration: the store is ``<data_dir>/programs``;
5. ``./cnc-data/programs``, relative to the working directory at start.

The command line beats the configuration file (as ``--cycle-ms`` does); on each level the
store's own directory beats the data directory that contains it. Relative paths, also
those of the configuration, are taken from the working directory at start; ``~`` is
expanded. Two services started from different directories therefore never share
programs, and a service restarted where it was started finds its programs again.

The output area (the files the kernel writes: ``#MSG SAVE``, logs) is a directory of its
own, never the store: ``--output-dir DIR``, else ``output_dir`` of the configuration, else
``<data dir>/output`` when the store is ``<data dir>/programs`` (cases 2, 4 and 5), else
``<store>-output`` beside a store given by itself (``--program-dir /data/progs`` writes
to ``/data/progs-output``). ``output_area_location`` refuses one that is the store, or
inside it, or contains it.

The operator data (tool list, zero offsets: ``operator_data_location``) is a file in the
data directory, or beside a store given by itself.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

DEFAULT_DATA_DIR = Path("cnc-data")
PROGRAMS_SUBDIR = "programs"
OUTPUT_SUBDIR = "output"
OUTPUT_SUFFIX = "-output"
OPERATOR_DATA_NAME = "operator-data.json"  # tool list and zero offsets (operator_data_store)


@dataclass(frozen=True, slots=True)
class StoreLocation:
    """The program store's absolute directory and what chose it (for the start-up log)."""

    path: Path
    source: str
    data_dir: Path | None = None  # the data directory the store is programs/ of, if so


def program_store_location(
    program_dir: Path | None,
    data_dir: Path | None,
    config_program_dir: str | None,
    config_data_dir: str | None,
    cwd: Path | None = None,
) -> StoreLocation:
    """The program store of a service started in ``cwd`` (default: the working directory)
    with these options and configuration keys; see the module docstring for the order."""
    base = cwd if cwd is not None else Path.cwd()
    candidates = (
        (program_dir, "", "--program-dir"),
        (data_dir, PROGRAMS_SUBDIR, "--data-dir"),
        (config_program_dir, "", "program_store_dir of the configuration"),
        (config_data_dir, PROGRAMS_SUBDIR, "data_dir of the configuration"),
    )
    for given, below, source in candidates:
        if given:  # an empty string in the configuration means "not set"
            data_dir = _absolute(base, Path(given)) if below else None
            return StoreLocation(_absolute(base, Path(given) / below), source, data_dir)
    return StoreLocation(
        _absolute(base, DEFAULT_DATA_DIR / PROGRAMS_SUBDIR),
        f"default: {DEFAULT_DATA_DIR / PROGRAMS_SUBDIR} in the working directory",
        _absolute(base, DEFAULT_DATA_DIR),
    )


def output_area_location(
    output_dir: Path | None,
    config_output_dir: str | None,
    store: StoreLocation,
    cwd: Path | None = None,
) -> StoreLocation:
    """The output area of a service whose program store is ``store`` (see the module
    docstring); ``ValueError`` when it would be the store, inside it or around it."""
    base = cwd if cwd is not None else Path.cwd()
    if output_dir is not None:
        found = StoreLocation(_absolute(base, output_dir), "--output-dir")
    elif config_output_dir:
        found = StoreLocation(_absolute(base, Path(config_output_dir)),
                              "output_dir of the configuration")
    elif store.data_dir is not None:
        found = StoreLocation(store.data_dir / OUTPUT_SUBDIR,
                              f"{OUTPUT_SUBDIR}/ in the data directory")
    else:
        found = StoreLocation(store.path.with_name(store.path.name + OUTPUT_SUFFIX),
                              "beside the program store")
    out, programs = found.path, store.path
    if out == programs or out.is_relative_to(programs) or programs.is_relative_to(out):
        raise ValueError(f"the output area {out} ({found.source}) must not be the program "
                         f"store {programs}, nor inside it, nor contain it")
    return found


def operator_data_location(
    data_dir: Path | None,
    config_data_dir: str | None,
    store: StoreLocation,
    cwd: Path | None = None,
) -> StoreLocation:
    """The file that keeps the tool list and zero offsets across restarts:
    ``operator-data.json`` in the data directory (``--data-dir``, else ``data_dir`` of the
    configuration, else the one the store is ``programs/`` of), else beside a store given
    by itself (``/data/progs`` keeps ``/data/progs-operator-data.json``)."""
    base = cwd if cwd is not None else Path.cwd()
    if data_dir is not None:
        return StoreLocation(_absolute(base, data_dir) / OPERATOR_DATA_NAME, "--data-dir")
    if config_data_dir:
        return StoreLocation(_absolute(base, Path(config_data_dir)) / OPERATOR_DATA_NAME,
                             "data_dir of the configuration")
    if store.data_dir is not None:
        return StoreLocation(store.data_dir / OPERATOR_DATA_NAME, "in the data directory")
    return StoreLocation(store.path.with_name(f"{store.path.name}-{OPERATOR_DATA_NAME}"),
                         "beside the program store")


def _absolute(base: Path, path: Path) -> Path:
    # resolve(): the logged path is the one a user can cd to, without ``..`` or links
    return (base / path.expanduser()).resolve()
