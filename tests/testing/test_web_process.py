"""``WebProcess.stop``: SIGINT first, and a cnc-web that does not end within
``STOP_TIMEOUT_S`` is killed (cnc-web itself ends at once now; this is the harness's
guard against one that hangs)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from cnc_objects.testing import web

# a process that ignores SIGINT, says so, and would otherwise sleep for a minute
_DEAF = ("import signal, sys, time\nsignal.signal(signal.SIGINT, signal.SIG_IGN)\n"
         "print('ready', flush=True)\ntime.sleep(60)\n")


def test_a_process_deaf_to_sigint_is_killed_after_the_timeout(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(web, "STOP_TIMEOUT_S", 0.2)
    process = subprocess.Popen([sys.executable, "-c", _DEAF], stdout=subprocess.PIPE)
    assert process.stdout is not None and process.stdout.readline() == b"ready\n"
    assert web.WebProcess(process, "http://127.0.0.1:1").stop() == -9  # SIGKILL
    process.stdout.close()


def test_an_ended_process_gives_its_exit_code() -> None:
    process = subprocess.Popen([sys.executable, "-c", "raise SystemExit(3)"])
    process.wait()
    assert web.WebProcess(process, "http://127.0.0.1:1").stop() == 3
