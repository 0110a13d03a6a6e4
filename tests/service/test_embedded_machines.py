"""The embedded machines ``--machine`` chooses, and a channel's kinematics in the
configuration (issue 39, docs/configuration.md "Embedded machines")."""

from __future__ import annotations

import copy
from typing import Any

import pytest

from cnc_objects.service.config import ConfigError, build_config
from cnc_objects.service.machine_config import (
    EMBEDDED_MACHINES,
    FIVE_AXIS_AC,
    EmbeddedMachine,
)


@pytest.mark.parametrize("machine", list(EmbeddedMachine))
def test_every_embedded_machine_is_valid(machine: EmbeddedMachine) -> None:
    config = build_config(machine=machine)
    chain = config.channels[0].kinematic_chain()
    five_axis = machine != EmbeddedMachine.THREE_AXIS
    assert (chain is not None) == five_axis
    assert [a.axis_type for a in config.channels[0].axes].count("rotary") == 2 * five_axis
    assert set(EMBEDDED_MACHINES) == set(EmbeddedMachine)


def test_the_ac_machine_turns_its_cradle_about_a_line_below_the_table() -> None:
    chain = build_config(machine=EmbeddedMachine.FIVE_AXIS_AC).channels[0].kinematic_chain()
    assert chain is not None
    # A = 90: the spindle nose at the table's centre (0, 0, 0), seen from the workpiece
    # turned by -90 about the cradle's line (y 0, z -100): relative (0, 0, 100) ->
    # (0, 100, 0), back on the line (0, 100, -100); the tool points along the
    # workpiece's +Y
    pose = chain.forward({3: 90.0})
    assert pose.tip_mm == pytest.approx((0.0, 100.0, -100.0))
    assert pose.orientation == pytest.approx((0.0, 1.0, 0.0))


def _ac_with(change: Any) -> dict[str, Any]:
    machine = copy.deepcopy(FIVE_AXIS_AC)
    change(machine["channels"][0]["kinematics"])
    return machine


@pytest.mark.parametrize(("change", "message"), [
    (lambda k: k["axes"][0].update(axis="W"), "no axis 'W' in the channel"),
    (lambda k: k["axes"][0].update(type="translator"),
     "C is a translator in the chain but a rotary axis"),
    (lambda k: k["axes"].pop(), "at least 5 items"),
    (lambda k: k["axes"][4].update(axis="X"), "an axis is in the chain twice"),
    (lambda k: k["axes"][2].update(axis="A", type="translator"), "is a translator in the"),
    (lambda k: k["axes"][3].update(direction=(1.0, 0.0, 0.0)), "do not span space"),
])
def test_a_bad_chain_is_refused_with_its_reason(change: Any, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        # build_config merges over the embedded machine: start from the default here
        build_config(_ac_with(change), machine=EmbeddedMachine.THREE_AXIS)
