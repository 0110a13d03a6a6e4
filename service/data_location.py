"""Where a service keeps its data: the program store's directory, and why there.

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
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

DEFAULT_DATA_DIR = Path("cnc-data")
PROGRAMS_SUBDIR = "programs"


@dataclass(frozen=True, slots=True)
class StoreLocation:
    """The program store's absolute directory and what chose it (for the start-up log)."""

    path: Path
    source: str


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
            return StoreLocation(_absolute(base, Path(given) / below), source)
    return StoreLocation(
        _absolute(base, DEFAULT_DATA_DIR / PROGRAMS_SUBDIR),
        f"default: {DEFAULT_DATA_DIR / PROGRAMS_SUBDIR} in the working directory",
    )


def _absolute(base: Path, path: Path) -> Path:
    # resolve(): the logged path is the one a user can cd to, without ``..`` or links
    return (base / path.expanduser()).resolve()
