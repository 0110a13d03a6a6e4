"""The reliability suite (issue 21): fuzzed frames and NC programs, load, faults and
extreme values against a real service on loopback. ``make test`` runs it at its quick
scale; ``pytest tests/reliability --soak`` (or ``CNC_SOAK=1``) at the soak scale."""
