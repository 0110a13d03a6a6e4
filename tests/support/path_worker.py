"""A child process that runs programs on an in-process kernel, for comparing module sets.

``python -m tests.support.path_worker`` (from the repository root) first prints one line,
``compiled`` or ``pure``: which path modules this process imported (``CNC_NATIVE=0``
forces pure Python; ``cnc_objects._native``). Then, for every line of JSON on stdin
(``{"text": ..., "event_speed": bool, "periods": [...], "writes": [[cycle, kind, value],
...]}``), it runs ``test_event_speed_clock.run`` and prints one line of JSON: the end
cycle, the channel state then and, for every published cycle in order, ``[cycle, repr(values)]`` (``repr``
round-trips floats exactly, so equal texts are equal bits). A run that fails prints
``{"error": ...}`` and the worker goes on.

One worker serves a whole hypothesis property: the interpreter and the modules are
loaded once, not once per example.
"""

from __future__ import annotations

import json
import sys
import traceback


def main() -> None:
    """Serve runs until stdin ends."""
    from cnc_objects import _native
    from cnc_objects.service.kernel.path import interpolator, segments
    from tests.support.event_speed import run
    from tests.support.nc_strategies import to_commands

    compiled = _native.compiled(segments) and _native.compiled(interpolator)
    print("compiled" if compiled else "pure", flush=True)
    for line in sys.stdin:
        job = json.loads(line)
        try:
            recording = run(job["text"], job["event_speed"], tuple(job["periods"]),
                            to_commands([tuple(w) for w in job["writes"]]))
            values = recording.values
            reply: dict[str, object] = {
                "end": recording.end_cycle, "state": values[recording.end_cycle][9],
                "cycles": [[cycle, repr(values[cycle])] for cycle in sorted(values)]}
        except Exception:  # the parent reports it with the program
            reply = {"error": traceback.format_exc()}
        print(json.dumps(reply), flush=True)


if __name__ == "__main__":
    main()
