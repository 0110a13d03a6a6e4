"""docs/testing.md shows the example files as they are (the packaging tests run them)."""

from __future__ import annotations

from tests.support.service import ROOT

DOCS = ROOT / "docs"


def test_the_guide_shows_the_example_test_and_program_verbatim() -> None:
    guide = (DOCS / "testing.md").read_text()
    for name, fence in (("test_example_part.py", "```python\n"), ("example-part.nc", "```\n")):
        text = (DOCS / "examples" / name).read_text()
        assert f"{fence}{text}```\n" in guide, name
