"""cnc-hmi in tests: the app driven by textual's pilot at a size its tables fit, and
waits on what it shows."""

from __future__ import annotations

import time
from collections.abc import Callable

from textual.pilot import Pilot

from cnc_objects.clients.hmi.app import HmiApp

SIZE = (110, 48)  # the HMI's tables want about 110 columns

WAIT_S = 15.0  # generous: the machine running the tests may be busy


# 20 blocks of 1 mm at 1 mm/min: 1200 s of kernel time, many seconds of wall time even
# with the virtual clock (it runs 100x real time and more: 200 s once ran out before the
# HMI showed the resumed program ACTIVE), so the keys act while it runs. The marked area
# is for look-ahead mode 1.
LONG_PROGRAM = "\n".join(
    ["N5 G90 G17", "N8 #CONTOUR LOOKAHEAD LOG ON [PARAM=7]"]
    # 40 mm blocks at 1 mm/min: 13 h of machining, seconds of wall time under the
    # event-speed virtual clock, so that the keys catch the program running
    + [f"N{10 * k} G1 X{40 * k} Y{k % 2} F1" for k in range(1, 21)]
    + ["N300 #CONTOUR LOOKAHEAD LOG OFF", "N310 M30", ""]
).encode()


async def wait_until(
    pilot: Pilot, predicate: Callable[[], bool], timeout_s: float = WAIT_S,
    what: str | Callable[[], str] = "",
) -> None:
    """Let the app run until ``predicate()`` holds; fail after ``timeout_s``, saying
    ``what`` (a callable: what the app shows at that moment)."""
    deadline = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > deadline:
            said = what() if callable(what) else what
            raise AssertionError(f"not within {timeout_s:g} s: {said or predicate}")
        await pilot.pause()


def shown(app: HmiApp) -> Callable[[], str]:
    """What the app shows of channel 1 and its message line, for a failure message."""
    return lambda: (f"ch1 {app.channels.cell('ch1', 'state')} at block "
                    f"{app.channels.cell('ch1', 'block')!r}; message {app.message.text!r}")


def filled(app: HmiApp) -> bool:
    """Connected, and every cell of both tables has a value from the service."""
    if app.client is None or app.machine is None or not app.axes.row_count:
        return False
    cells = [str(c) for t in (app.channels, app.axes) for row in range(t.row_count)
             for c in t.get_row_at(row)]
    return "…" not in cells


async def started(pilot: Pilot) -> HmiApp:
    app = pilot.app
    assert isinstance(app, HmiApp)
    await wait_until(pilot, lambda: filled(app), what="tables filled from the service")
    return app
