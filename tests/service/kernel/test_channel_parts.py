"""A channel is made of immutable parts, each replaced only by the modules that own it
(``kernel/channel_parts.py`` names them): the source is read, so a new assignment from
anywhere else fails here before it can change a value behind its owner's back."""

from __future__ import annotations

import ast
import dataclasses
from pathlib import Path

import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel import channel_parts
from cnc_objects.service.kernel.kernel_state import KernelState
from cnc_objects.service.kernel.state import Channel

KERNEL = Path(__file__).resolve().parents[3] / "service" / "kernel"

# part -> the modules (of service/kernel) that may assign it
OWNERS: dict[str, set[str]] = {
    "switches": {"commands", "commands_operator"},
    "suspend": {"commands", "switchover"},
    "program": {"channel_run", "program_run", "channel_check"},
    "block": {"channel_run", "program_run", "channel_check"},
    "path": {"channel_run", "program_run", "channel_check"},
    "errors": {"channel_run", "channel_check"},
    "manual": {"manual_mode"},
    "tooling": {"channel_run", "tooling"},
    "tool_cut_cycles": {"tool_life", "commands_tooling"},
    "contour": {"commands", "channel_run", "program_run"},
    "spindle": {"spindle"},
    "plc_functions": {"plc_functions"},
}
# the names a channel goes by in the kernel's modules
CHANNEL_NAMES = {"ch", "channel", "self.channel", "self._channel", "runner.channel",
                 "self._shown", "shown"}
IMMUTABLE_PARTS = ("switches", "suspend", "program", "block", "path", "errors")


def _assignments() -> list[tuple[str, str, int]]:
    """(part, module, line) of every assignment to a channel's part in the kernel."""
    found = []
    for path in sorted(KERNEL.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            targets: list[ast.expr] = []
            if isinstance(node, ast.Assign):
                targets = node.targets
            elif isinstance(node, (ast.AugAssign, ast.AnnAssign)):
                targets = [node.target]
            else:
                continue
            for target in targets:
                for element in target.elts if isinstance(target, ast.Tuple) else [target]:
                    if (isinstance(element, ast.Attribute) and element.attr in OWNERS
                            and ast.unparse(element.value) in CHANNEL_NAMES):
                        found.append((element.attr, path.stem, node.lineno))
    return found


def test_only_the_owners_replace_a_part() -> None:
    assignments = _assignments()
    strangers = [f"{module}.py:{line} assigns {part} (owners: {sorted(OWNERS[part])})"
                 for part, module, line in assignments if module not in OWNERS[part]]
    assert strangers == []
    assert {part for part, _, _ in assignments} == set(OWNERS)  # the check sees them all


def test_the_channel_is_its_identity_axes_mode_state_and_parts() -> None:
    names = {f.name for f in dataclasses.fields(Channel)}
    assert names == {"channel_id", "name", "axes", "mode", "state", "wait_reason"} | set(OWNERS)


@pytest.mark.parametrize("part", IMMUTABLE_PARTS)
def test_a_part_cannot_be_changed_in_place(part: str) -> None:
    channel = KernelState.from_config(build_config()).channels[0]
    value = getattr(channel, part)
    names: tuple[str, ...] = getattr(value, "_fields", ())  # a NamedTuple's
    field = names[0] if names else dataclasses.fields(value)[0].name
    with pytest.raises((AttributeError, dataclasses.FrozenInstanceError)):
        setattr(value, field, getattr(value, field))


def test_the_snapshot_shares_the_parts_and_copies_the_axes() -> None:
    channel = KernelState.from_config(build_config()).channels[0]
    frozen = channel.frozen()
    for part in OWNERS:
        assert getattr(frozen, part) is getattr(channel, part)
    assert frozen.axes == channel.axes and frozen.axes[0] is not channel.axes[0]
    assert channel_parts.__doc__ is not None and all(
        f"``{part}``" in channel_parts.__doc__ for part in OWNERS)
