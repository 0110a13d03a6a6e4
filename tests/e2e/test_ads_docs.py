"""docs/ads.md runs as written: its pyads examples against a real service.

Every ```python block of the page runs, in order, in one fresh Python process (one pyads
session, as a reader would type them); the ```text block that follows a python block is
the output that block must print. The page is written for ``make run`` (127.0.0.1); here
the service has a loopback address of its own, put in place of 127.0.0.1.
"""

from __future__ import annotations

import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from cnc_objects.testing import ServiceProcess, start_service

PAGE = Path(__file__).resolve().parents[2] / "docs" / "ads.md"
FENCE = re.compile(r"^```(\w*)\n(.*?)^```$", re.MULTILINE | re.DOTALL)
MARKER = "@@ block {} @@"


def examples(text: str) -> list[tuple[str, str]]:
    """(code, expected output) of each python block; output "" when no text block follows."""
    out: list[tuple[str, str]] = []
    for match in FENCE.finditer(text):
        kind, body = match.group(1), match.group(2)
        if kind == "python":
            out.append((body, ""))
        elif kind == "text" and out and out[-1][1] == "":
            out[-1] = (out[-1][0], body)
    return out


@pytest.fixture(scope="module")
def service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    service = start_service(program_dir=tmp_path_factory.mktemp("ads-docs"), ads=True)
    yield service
    assert service.stop() == 0, service.log_text


def test_the_page_has_the_examples_the_issue_asks_for() -> None:
    code = "\n".join(c for c, _ in examples(PAGE.read_text()))
    for call in ("pyads.Connection(", ", 851,", ", 551,", ", 553,", "read_by_name(",
                 "pyads.PLCTYPE_", ".read(", ".write(", "read_list_by_name(",
                 "get_all_symbols(", "add_device_notification(", "get_handle("):
        assert call in code, call


def test_every_example_prints_what_the_page_shows(service: ServiceProcess) -> None:
    blocks = examples(PAGE.read_text())
    host = service.ads_address[0]  # type: ignore[index]
    assert service.ams_net_id == f"{host}.1.1"
    script = "\n".join(f"print({MARKER.format(k)!r}, flush=True)\n{code}"
                       for k, (code, _) in enumerate(blocks))
    result = subprocess.run([sys.executable, "-c", script.replace("127.0.0.1", host)],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    printed = re.split(r"^@@ block \d+ @@\n", result.stdout, flags=re.MULTILINE)[1:]
    assert len(printed) == len(blocks), result.stdout
    for k, ((code, expected), got) in enumerate(zip(blocks, printed)):
        assert got.strip() == expected.strip(), f"block {k}:\n{code}"
