"""Start the real ``cnc-service`` in a subprocess on a free port, for end-to-end tests.

The service binds ``tcp://127.0.0.1:*`` (ZeroMQ picks a free port, no race) and logs the
endpoint it got; we wait for that log line, never for a fixed time.
"""

from __future__ import annotations

import contextlib
import queue
import re
import signal
import subprocess
import sys
import tempfile
import threading
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

_LISTENING = re.compile(r"listening on (tcp://\S+)")
ROOT = Path(__file__).resolve().parents[2]


@dataclass
class RunningService:
    """A service process, its endpoint and everything it logged so far."""

    process: subprocess.Popen
    endpoint: str
    log: list[str] = field(default_factory=list)
    _lines: queue.Queue = field(default_factory=queue.Queue)

    def stop(self, timeout_s: float = 10.0) -> int:
        """SIGINT, then wait for the exit code."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
        return self.process.wait(timeout_s)

    def wait_for_log(self, pattern: str, timeout_s: float = 10.0) -> str:
        """The first log line (from now on, or already logged) matching ``pattern``."""
        regex = re.compile(pattern)
        for line in self.log:
            if regex.search(line):
                return line
        while True:
            line = self._lines.get(timeout=timeout_s)
            if line is None:
                raise AssertionError(f"service exited before logging {pattern!r}")
            if regex.search(line):
                return line


@contextlib.contextmanager
def serving(*args: str) -> Iterator[RunningService]:
    """``start_service(*args)`` for a ``with`` block; on leaving, the service must stop
    cleanly (exit code 0), else the test fails with its log."""
    service = start_service(*args)
    try:
        yield service
    finally:
        assert service.stop() == 0, "\n".join(service.log)


def start_service(*args: str, timeout_s: float = 20.0) -> RunningService:
    """Start ``cnc-service --clock virtual`` (unless args say otherwise) and wait until
    it listens. Raises with the service's log when it does not come up."""
    argv = [sys.executable, "-m", "cnc_objects.service.main", "--endpoint", "tcp://127.0.0.1:*"]
    if "--clock" not in args:
        argv += ["--clock", "virtual"]
    if "--program-dir" not in args:  # every test service gets an empty store of its own
        argv += ["--program-dir", tempfile.mkdtemp(prefix="cnc-programs-")]
    proc = subprocess.Popen(
        [*argv, *args], cwd=ROOT, stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True
    )
    lines: queue.Queue = queue.Queue()
    log: list[str] = []

    def pump() -> None:  # keep reading so the pipe never fills up
        for line in proc.stderr:  # type: ignore[union-attr]
            log.append(line.rstrip("\n"))
            lines.put(line)
        lines.put(None)

    threading.Thread(target=pump, name="service-log", daemon=True).start()
    while True:
        try:
            line = lines.get(timeout=timeout_s)
        except queue.Empty:
            proc.kill()
            raise AssertionError(
                "service did not log 'listening on' in time:\n" + "\n".join(log)
            ) from None
        if line is None:
            proc.wait()
            raise AssertionError(
                f"service exited with {proc.returncode} before listening:\n" + "\n".join(log)
            )
        match = _LISTENING.search(line)
        if match:
            return RunningService(proc, match.group(1), log, lines)
