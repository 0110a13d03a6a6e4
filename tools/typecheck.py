"""Run mypy over the package as users import it (``cnc_objects.protocol`` ...).

The package's subpackages live in the repository's top-level folders and reach
``cnc_objects`` through setuptools' ``package-dir`` (docs/design-notes.md, "One import
namespace"); the editable install maps them with an import hook that mypy cannot follow.
So this script lays out ``build/typecheck/cnc_objects`` as symbolic links to the real
folders, points mypy at it, and shows every finding at the real file's path.

    python tools/typecheck.py                 # the whole package, pyproject's settings
    python tools/typecheck.py FILE ...        # a user's script against the package
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TREE = ROOT / "build" / "typecheck"
#: subpackage -> the folder it comes from (pyproject's [tool.setuptools.package-dir])
FOLDERS = {"protocol": "protocol", "objects": "objects", "service": "service",
           "clients": "clients"}


def link_tree() -> Path:
    """``build/typecheck`` with ``cnc_objects`` laid out as an installed wheel has it."""
    package = TREE / "cnc_objects"
    package.mkdir(parents=True, exist_ok=True)
    links = {name: ROOT / folder for name, folder in FOLDERS.items()}
    links |= {entry.name: entry for entry in (ROOT / "cnc_objects").iterdir()
              if entry.name != "__pycache__"}
    for name, target in links.items():
        link = package / name
        if link.is_symlink() and Path(os.readlink(link)) == target:
            continue
        if link.is_symlink() or link.exists():
            link.unlink()
        link.symlink_to(target)
    return TREE


def real_path(line: str) -> str:
    """A mypy line with the link tree's path replaced by the repository's."""
    prefix = str(link_tree() / "cnc_objects") + os.sep
    for name, folder in FOLDERS.items():
        line = line.replace(f"{prefix}{name}{os.sep}", f"{folder}{os.sep}")
        line = line.replace(f"build/typecheck/cnc_objects/{name}/", f"{folder}/")
    return line.replace("build/typecheck/cnc_objects/", "cnc_objects/")


def run(args: list[str]) -> tuple[str, str, int]:
    """mypy's (stdout, stderr, status) for ``args`` with the link tree on its path."""
    from mypy import api

    tree = link_tree()
    os.environ["MYPYPATH"] = str(tree)
    if not any(not a.startswith("-") for a in args):
        args = [*args, "-p", "cnc_objects"]
    out, err, status = api.run(["--config-file", str(ROOT / "pyproject.toml"), *args])
    return "".join(real_path(line) + "\n" for line in out.splitlines()), err, status


def main() -> int:
    out, err, status = run(sys.argv[1:])
    sys.stdout.write(out)
    sys.stderr.write(err)
    return status


if __name__ == "__main__":
    sys.exit(main())
