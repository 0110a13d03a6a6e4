"""The reliability suite's option (``--soak``) and its summary of measured figures.

    .venv/bin/python -m pytest tests/reliability -q --soak    # the long form (make soak)
    CNC_SOAK=1 .venv/bin/python -m pytest tests/reliability -q  # the same, from anywhere

``--soak`` is registered only when pytest starts with this directory among its paths (a
conftest below the root adds options only then); ``CNC_SOAK=1`` works in every case.
"""

from __future__ import annotations

import pytest

from tests.reliability import figures, scale


def pytest_addoption(parser: pytest.Parser) -> None:
    """``--soak``: run the reliability suite at its soak scale (see scale.py)."""
    parser.addoption("--soak", action="store_true", default=False,
                     help="reliability suite: the long form (100 000 frames, ...)")


def pytest_configure(config: pytest.Config) -> None:
    """Take ``--soak`` over into ``scale`` (the tests read it at run time)."""
    if config.getoption("--soak", default=False):
        scale.soak_option = True


def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter) -> None:
    """Print every figure the suite measured (docs/reliability.md quotes them)."""
    if not figures.FIGURES:
        return
    terminalreporter.section(f"reliability figures ({scale.current().name} scale)")
    for line in figures.table():
        terminalreporter.write_line(line)


@pytest.fixture
def run_scale() -> scale.Scale:
    """The counts of this run: quick (make test) or soak."""
    return scale.current()
