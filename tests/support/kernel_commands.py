"""Commands to a kernel in tests: submit one and wait until it was applied."""

from __future__ import annotations

import threading

from cnc_objects.service.kernel.commands import Refusal
from cnc_objects.service.kernel.kernel import Kernel


class Applied:
    """Collects the result of one submitted command; wait() blocks until it came."""

    def __init__(self) -> None:
        self.event = threading.Event()
        self.result: Refusal | None = None

    def __call__(self, result: Refusal | None) -> None:
        self.result = result
        self.event.set()

    def wait(self) -> Refusal | None:
        assert self.event.wait(5), "the kernel did not apply the command"
        return self.result


def submit(kernel: Kernel, command) -> Refusal | None:
    """Submit ``command`` and wait until the kernel applied it: its refusal or None."""
    done = Applied()
    kernel.submit(command, done)
    return done.wait()
