"""The wheel of this checkout, built once per session for the packaging tests."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BUILD_TIMEOUT_S = 300.0
# Not part of a source distribution: state of this checkout and of its tools. A stale
# build/ in particular could add or hide modules, so the wheel is built from a copy.
_NOT_SOURCE = shutil.ignore_patterns(".git", ".venv", "build", "dist", "*.egg-info",
                                     "__pycache__", ".pytest_cache", ".hypothesis")


@pytest.fixture(scope="session")
def wheel(wheel_build: tuple[Path, str]) -> Path:
    """The wheel of this checkout (see ``wheel_build``)."""
    return wheel_build[0]


@pytest.fixture(scope="session")
def wheel_build(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """(the wheel, what the build printed): ``pip wheel --no-deps --no-build-isolation``
    of a copy of this checkout, offline (``--no-index``): the build uses the setuptools
    installed with the test extra."""
    source = tmp_path_factory.mktemp("source") / "cnc-objects"
    shutil.copytree(ROOT, source, ignore=_NOT_SOURCE, symlinks=True)
    out = tmp_path_factory.mktemp("wheel")
    built = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
         "--no-index", "--disable-pip-version-check", "-w", str(out), str(source)],
        capture_output=True, text=True, timeout=BUILD_TIMEOUT_S,
    )
    assert built.returncode == 0, (
        "pip wheel failed (the test extra must bring setuptools>=77 and wheel):\n"
        f"{built.stdout}{built.stderr}")
    [path] = out.glob("*.whl")
    return path, built.stdout + built.stderr
