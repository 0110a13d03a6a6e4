"""Lines of the package that a test ran before a change and none runs after it.

    python tools/coverage_diff.py BEFORE.json AFTER.json --before-commit SHA

BEFORE.json and AFTER.json are coverage.py JSON reports (``make coverage`` writes
``build/coverage.json``); SHA is the commit BEFORE.json was measured on. Line numbers move
when code changes, so each file of the report before is matched to its file now (git's
rename detection follows moved modules) and its lines to the lines now by ``difflib``:
a line covered before counts as lost when it is still in the code, unchanged, and no
test runs it now. Edited or removed lines are not compared (they are other code). Exit
status 1 when a line was lost, with the lines listed.
"""

from __future__ import annotations

import argparse
import difflib
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _renames(commit: str) -> dict[str, str]:
    """Old path -> new path for the files git sees as moved since ``commit``."""
    done = subprocess.run(["git", "diff", "--name-status", "-M", commit, "--", "."],
                          capture_output=True, text=True, check=True, cwd=ROOT)
    moved = {}
    for line in done.stdout.splitlines():
        status, *paths = line.split("\t")
        if status.startswith("R") and len(paths) == 2:
            moved[paths[0]] = paths[1]
    return moved


def _old_text(commit: str, path: str) -> list[str]:
    done = subprocess.run(["git", "show", f"{commit}:{path}"], capture_output=True, text=True,
                          check=True, cwd=ROOT)
    return done.stdout.splitlines()


def _line_map(old: list[str], new: list[str]) -> dict[int, int]:
    """1-based old line -> new line, for the lines that stayed the same."""
    matcher = difflib.SequenceMatcher(a=old, b=new, autojunk=False)
    mapped = {}
    for block in matcher.get_matching_blocks():
        for k in range(block.size):
            mapped[block.a + k + 1] = block.b + k + 1
    return mapped


def lost_lines(before: dict[str, object], after: dict[str, object],
               commit: str) -> list[tuple[str, int, str]]:
    """(path now, line now, text) of every unchanged line covered before and not now."""
    moved = _renames(commit)
    files_before: dict[str, dict[str, list[int]]] = before["files"]  # type: ignore[assignment]
    files_after: dict[str, dict[str, list[int]]] = after["files"]  # type: ignore[assignment]
    lost = []
    for old_path, measured in files_before.items():
        new_path = moved.get(old_path, old_path)
        if new_path not in files_after or not (ROOT / new_path).exists():
            continue  # the module is gone or no test imports it now: listed below
        old, new = _old_text(commit, old_path), (ROOT / new_path).read_text().splitlines()
        mapped = _line_map(old, new)
        covered_now = set(files_after[new_path]["executed_lines"])
        for line in measured["executed_lines"]:
            now = mapped.get(line)
            if now is not None and now not in covered_now:
                lost.append((new_path, now, new[now - 1].strip()))
    for old_path in files_before:
        new_path = moved.get(old_path, old_path)
        if (ROOT / new_path).exists() and new_path not in files_after:
            lost.append((new_path, 0, "(the whole module: no test imports it now)"))
    return lost


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("before", type=Path)
    parser.add_argument("after", type=Path)
    parser.add_argument("--before-commit", required=True)
    args = parser.parse_args(argv)
    before, after = (json.loads(p.read_text()) for p in (args.before, args.after))
    totals = [report["totals"] for report in (before, after)]
    print("covered lines: before {} of {} ({:.1f} %), after {} of {} ({:.1f} %)".format(
        totals[0]["covered_lines"], totals[0]["num_statements"], totals[0]["percent_covered"],
        totals[1]["covered_lines"], totals[1]["num_statements"], totals[1]["percent_covered"]))
    lost = lost_lines(before, after, args.before_commit)
    for path, line, text in lost:
        print(f"{path}:{line}: covered before, not now: {text}")
    print(f"{len(lost)} unchanged lines covered before and not now")
    return 1 if lost else 0


if __name__ == "__main__":
    sys.exit(main())
