"""Node.js with the npm packages of a directory of tests/ installed from its lock file
(``npm ci`` when missing; ``.ci/run`` does it beforehand): for the clients no one here
wrote (ads-client, node-opcua). Without Node.js and npm the test is skipped, saying so."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

NPM_CI_TIMEOUT_S = 600


def node_with(directory: Path, package: str, who: str) -> str:
    """The path of ``node`` once ``directory`` has ``package`` in its node_modules;
    ``who`` names what needs it in the skip reason."""
    node_path, npm = shutil.which("node"), shutil.which("npm")
    if node_path is None or npm is None:
        pytest.skip(f"{who} needs Node.js and npm: apt-get install nodejs npm")
    if not (directory / "node_modules" / package).is_dir():
        installed = subprocess.run(
            [npm, "ci", "--no-audit", "--no-fund"], cwd=directory, capture_output=True,
            text=True, timeout=NPM_CI_TIMEOUT_S, check=False)
        assert installed.returncode == 0, f"npm ci failed:\n{installed.stderr[-2000:]}"
    return node_path
