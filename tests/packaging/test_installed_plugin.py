"""A user's project: cnc-objects installed from the wheel into a fresh venv, the example
test of docs/testing.md copied in, pytest run there. The plugin must come from the
installed wheel through its entry point (the project has no conftest.py), and must work
without pytest-asyncio.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

from tests.packaging.conftest import ROOT

EXAMPLES = ROOT / "docs" / "examples"
RUN_TIMEOUT_S = 300.0
# Left out of the dependencies the venv borrows: the checkout's own install (the wheel
# must stand alone) and pytest-asyncio (the plugin must not need it).
_NOT_BORROWED = ("cnc_objects", "__editable__", "pytest_asyncio")


def run(*argv: str | Path, cwd: Path,
        timeout_s: float = RUN_TIMEOUT_S) -> subprocess.CompletedProcess[str]:
    """Run ``argv`` in ``cwd`` with an environment free of this session's Python and
    pytest settings."""
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("PYTHON", "PYTEST_", "VIRTUAL_ENV", "COV_"))}
    return subprocess.run([str(a) for a in argv], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=timeout_s)


@pytest.fixture(scope="module")
def venv(wheel: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A fresh venv with the wheel installed; every other package is borrowed from this
    session's environment through a .pth file (the tests run offline)."""
    base = tmp_path_factory.mktemp("user")
    borrowed = base / "borrowed"
    borrowed.mkdir()
    here = {Path(sysconfig.get_paths()[key]) for key in ("purelib", "platlib")}
    for site in here:
        for entry in site.iterdir():
            if not entry.name.startswith(_NOT_BORROWED) and entry.suffix != ".pth" \
                    and not (borrowed / entry.name).exists():
                (borrowed / entry.name).symlink_to(entry)
    venv = base / "venv"
    made = run(sys.executable, "-m", "venv", "--without-pip", venv, cwd=base, timeout_s=60)
    assert made.returncode == 0, made.stderr
    python = venv / "bin" / "python"
    site = run(python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])",
               cwd=base, timeout_s=60)
    (Path(site.stdout.strip()) / "borrowed.pth").write_text(f"{borrowed}\n")
    installed = run(python, "-m", "pip", "install", "--no-deps", "--no-index",
                    "--disable-pip-version-check", wheel, cwd=base)
    assert installed.returncode == 0, installed.stdout + installed.stderr
    return venv


@pytest.fixture
def project(tmp_path: Path) -> Path:
    """An empty project with the example test and its program, as docs/testing.md says."""
    for name in ("test_example_part.py", "example-part.nc"):
        shutil.copy(EXAMPLES / name, tmp_path / name)
    return tmp_path


def test_the_example_passes_with_the_plugin_from_the_wheel(venv: Path, project: Path) -> None:
    done = run(venv / "bin" / "python", "-m", "pytest", "-p", "no:cacheprovider",
               "--trace-config", cwd=project)
    out = done.stdout + done.stderr
    assert done.returncode == 0, out
    assert "4 passed" in out, out
    assert not list(project.rglob("conftest.py"))
    # registered through its entry point, from the venv's copy of the package
    plugin = [line for line in out.splitlines() if line.strip().startswith("cnc_objects ")]
    assert plugin and str(venv) in plugin[0], plugin or out
    assert "pytest_asyncio" not in out


def test_the_async_client_fixture_says_what_it_needs(venv: Path, project: Path) -> None:
    (project / "test_async.py").write_text("def test_wants(cnc_async_client):\n    pass\n")
    done = run(venv / "bin" / "python", "-m", "pytest", "-p", "no:cacheprovider",
               "test_async.py", cwd=project)
    assert done.returncode == 1, done.stdout + done.stderr
    assert "the cnc_async_client fixture needs pytest-asyncio: pip install pytest-asyncio" \
        in done.stdout, done.stdout


def test_the_console_scripts_run_from_the_venv(venv: Path, project: Path) -> None:
    done = run(venv / "bin" / "cnc-service", "--help", cwd=project, timeout_s=60)
    assert done.returncode == 0, done.stderr
    assert "--program-dir" in done.stdout
