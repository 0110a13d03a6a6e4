"""The tests are type-checked too, by a ratchet: mypy strict over ``tests/`` (through
``tools/typecheck.py``, the package as users import it) finds at most
``FINDINGS_MAX`` problems, and the number only goes down. When a change brings it below,
lower ``FINDINGS_MAX`` to the new count (the failure message says so only when it rises).

Issue 38 started at 1425 findings (820 test functions without ``-> None``; 574 of them
annotated since); docs/testing.md says how to see them.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FINDINGS_MAX = 1022
_FOUND = re.compile(r"^Found (\d+) errors? in \d+ files?", re.M)


def test_mypy_strict_over_the_tests_finds_no_more_than_before(tmp_path: Path) -> None:
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        import typecheck  # type: ignore[import-not-found]  # tools/ is not a package
    finally:
        sys.path.pop(0)
    # a cache of its own: other tests run mypy at the same time in other workers
    out, err, status = typecheck.run([str(ROOT / "tests"), "--no-incremental",
                                      "--cache-dir", str(tmp_path / "cache")])
    found = _FOUND.search(out)
    findings = int(found.group(1)) if found else 0
    assert status in (0, 1) and (found or status == 0), out[-3000:] + err[-3000:]
    assert findings <= FINDINGS_MAX, (
        f"mypy strict finds {findings} problems in tests/ (at most {FINDINGS_MAX} before): "
        f"the new ones are among\n{out[-5000:]}")
