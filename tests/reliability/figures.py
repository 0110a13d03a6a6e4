"""The figures the reliability tests measure, printed at the end of the run.

A test calls ``record(...)`` with what it measured and the command that reproduces it;
``conftest.py`` prints every figure in pytest's terminal summary (section "reliability
figures"), so ``make soak`` shows them without ``-s``. docs/reliability.md quotes them.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Figure:
    """One measured figure: what, its value (with unit), the test that measured it."""

    what: str
    value: str
    test: str


FIGURES: list[Figure] = []


def record(what: str, value: str, test: str) -> None:
    """Remember a figure for the summary; ``test`` is the node id that measures it."""
    FIGURES.append(Figure(what, value, test))


def table() -> list[str]:
    """The figures as aligned lines, in the order they were measured."""
    width = max((len(f.what) for f in FIGURES), default=0)
    return [f"{f.what:<{width}}  {f.value}   [{f.test}]" for f in FIGURES]
