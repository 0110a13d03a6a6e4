"""NC programs that decode without end and without a block (issue 35): the decoder must
see a RESET within bounded work, and its endless-program guard must end them."""

from __future__ import annotations


def nested_calls(depth: int = 19, fan: int = 4) -> str:
    """An MDI of local subprograms ``depth`` deep, each calling the next ``fan`` times:
    fan**depth calls, no loop, no block (the innermost only returns)."""
    lines = ["LL S1"]
    for k in range(1, depth + 1):
        lines.append(f"%L S{k}")
        lines += [f"LL S{k + 1}"] * (fan if k < depth else 0)
        lines.append("M17")
    return "\n".join(lines) + "\n"


def many_labels(count: int = 90_000) -> str:
    """``count`` label lines and a backward ``$GOTO`` to the first: endless, no block."""
    return "".join(f"N{k}:\n" for k in range(1, count + 1)) + "$GOTO N1\nM30\n"
