"""``cnc`` in tests: in this process through typer's ``CliRunner``, or as a subprocess.

Most tests check what a command prints and its exit code; starting a Python for each
call (about 0.3-0.5 s of imports) was 95 % of ``tests/clients``' time. ``cnc`` runs the
same ``app`` that the ``cnc`` script's ``main`` runs, in this process, and returns what a
subprocess would (``returncode``, ``stdout``, ``stderr``), so a test reads the same either
way. Where the process itself is the point (an environment variable read at import,
standard input, a signal, the entry points) ``cnc_process`` runs the real script; ``cnc``
falls back to it when given ``env``, because the CLI reads ``CNC_ENDPOINT`` when it is
imported.
"""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
import traceback
from pathlib import Path
from typing import Any

from typer.testing import CliRunner

from cnc_objects.clients.cli import app

ROOT = Path(__file__).resolve().parents[2]
CNC_SCRIPT = "from cnc_objects.clients.cli import main; main()"
SUBPROCESS_TIMEOUT_S = 60

_RUNNER = CliRunner()


def cnc(*args: str, endpoint: str | None = None, env: dict[str, str] | None = None,
        cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    """Run ``cnc ARGS`` in ``cwd`` (default: the project root) and return its exit code and
    output as a subprocess would give them; in this process unless ``env`` is given."""
    if env:
        return cnc_process(*args, endpoint=endpoint, env=env, cwd=cwd)
    argv = [*(["--endpoint", endpoint] if endpoint is not None else []), *args]
    with contextlib.chdir(cwd or ROOT):
        result = _RUNNER.invoke(app, argv, prog_name="cnc")
    stderr = result.stderr
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        # what the interpreter would have printed for an exception nobody caught
        stderr += "".join(traceback.format_exception(result.exception))
    return subprocess.CompletedProcess(["cnc", *argv], result.exit_code, result.stdout, stderr)


def cnc_process(*args: str, endpoint: str | None = None, env: dict[str, str] | None = None,
                cwd: Path | None = None, **run: Any) -> subprocess.CompletedProcess[str]:
    """Run ``cnc`` as a user would (the module entry point of the installed script), in
    ``cwd`` (default: the project root), with ``env`` over this process's environment."""
    argv = [sys.executable, "-c", CNC_SCRIPT]
    if endpoint is not None:
        argv += ["--endpoint", endpoint]
    return subprocess.run(
        [*argv, *args], cwd=cwd or ROOT, capture_output=True, text=True,
        timeout=SUBPROCESS_TIMEOUT_S, env={**os.environ, **(env or {})}, **run,
    )


def json_lines(result: subprocess.CompletedProcess[str]) -> list[dict[str, Any]]:
    """The JSON objects of ``--json`` output, one per line."""
    return [json.loads(line) for line in result.stdout.splitlines() if line.strip()]
