"""The README's guided tour, run as a user types it: every ``$ cnc ...`` line of the tour
sections, in order, in a fresh directory against a fresh service.

Lines that need a terminal or a broker (``cnc-hmi``, ``cnc watch``, the MQTT step, which
has its own tests) or files the README only names (``long.nc``, ``prog.nc``) are left out;
everything else must exit 0 (the lines that show a failure end in ``echo $?``).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

from tests.support.service import ROOT, RunningService

ILLUSTRATIVE = ("cnc watch", "cnc-hmi", "long.nc", "prog.nc", "mosquitto", "cnc-mqtt")
_COMMENT = re.compile(r"\s+#\s.*$")


def tour_commands() -> list[str]:
    """The ``$ `` lines of the README from "## 1." up to the first section after the tour."""
    text = (ROOT / "README.md").read_text()
    start = text.index("\n## 1. ")
    end = text.index("\n## ", text.index("\n## 7. ") + 1)
    commands = []
    for line in text[start:end].splitlines():
        if line.startswith("$ "):
            command = _COMMENT.sub("", line[2:]).strip()
            if not any(word in command for word in ILLUSTRATIVE):
                commands.append(command)
    return commands


def test_the_tour_has_its_steps() -> None:
    commands = tour_commands()
    for expected in ("cnc info", "cnc run part.nc --wait", "cnc plot part.nc -o part.png",
                     "cnc lookahead", "cnc mdi -c 2 --wait"):
        assert any(c.startswith(expected) for c in commands), expected


def test_every_tour_command_works(service: RunningService, tmp_path: Path) -> None:
    (tmp_path / "docs").symlink_to(ROOT / "docs")
    env = {**os.environ, "CNC_ENDPOINT": service.endpoint,
           "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    for command in tour_commands():
        done = subprocess.run(["bash", "-c", command], cwd=tmp_path, env=env,
                              capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, f"$ {command}\n{done.stdout}{done.stderr}"
    assert (tmp_path / "part.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
