"""Configuration: the embedded default machine, overrides, and errors that name the key."""

from __future__ import annotations

import pytest

from service.config import ConfigError, build_config


def test_default_machine() -> None:
    config = build_config()
    assert [a.number for a in config.physical_axes] == [1, 2, 3]
    main, jog = config.channels
    assert [(a.name, a.logical_number, a.link_to) for a in main.axes] == [
        ("X", 1, 1), ("Y", 2, 2), ("Z", 3, 3)
    ]
    assert jog.jog_of_path_only and jog.suspend_output_at_start
    assert [(a.logical_number, a.link_to, a.clone_of) for a in jog.axes] == [
        (11, 1, 1), (12, 2, 2), (13, 3, 3)
    ]
    assert main.axes[0].limits.vel_max_mm_s > 0 and main.axes[0].limits.acc_max_mm_s2 > 0


def test_tables_merge_and_arrays_replace() -> None:
    config = build_config({"cycle_ms": 2.0, "name": "lathe"})
    assert config.cycle_ms == 2.0 and config.name == "lathe" and len(config.channels) == 2


@pytest.mark.parametrize(
    ("overrides", "key"),
    [
        ({"cycle_ms": 0}, "cycle_ms"),
        ({"cycle_ms": "fast"}, "cycle_ms"),
        ({"unknown_key": 1}, "unknown_key"),
        ({"physical_axes": [{"number": 1, "name": "X"}, {"number": 1, "name": "Y"}]},
         "physical axis numbers repeat"),
        ({"channels": [{"id": 1, "name": "a", "axes": [
            {"name": "X", "logical_number": 1, "link_to": 9}]}]}, "channels.0.axes.0.link_to"),
        ({"channels": [{"id": 1, "name": "a", "axes": [
            {"name": "X", "logical_number": 1, "link_to": 1,
             "limits": {"sw_limit_min_mm": 5, "sw_limit_max_mm": 1}}]}]},
         "channels.0.axes.0.limits"),
        ({"channels": [{"id": 1, "name": "a", "axes": [
            {"name": "X", "logical_number": 1, "link_to": 1, "limits": {"vel_max_mm_s": -3}}]}]},
         "channels.0.axes.0.limits.vel_max_mm_s"),
        ({"channels": [{"id": 1, "name": "a", "axes": [
            {"name": "X", "logical_number": 1, "link_to": 1},
            {"name": "X", "logical_number": 2, "link_to": 2}]}]}, "axis names repeat"),
        ({"channels": []}, "channels"),
    ],
)
def test_bad_configuration_names_the_key(overrides: dict, key: str) -> None:
    with pytest.raises(ConfigError) as caught:
        build_config(overrides, "machine.toml")
    assert key in str(caught.value)
    assert str(caught.value).startswith("machine.toml: ")


def test_look_ahead_buffer_sizes_follow_p_chan_00650() -> None:
    def blocks(**channel) -> int:
        base = build_config().model_dump()["channels"][0]
        return build_config({"channels": [{**base, **channel}]}).channels[0].look_ahead_blocks

    assert blocks() == 120
    assert blocks(look_ahead="FCT_LOOK_AHEAD_LOW") == 30
    assert blocks(look_ahead="FCT_LOOK_AHEAD_HIGH") == 190
    assert blocks(look_ahead="FCT_LOOK_AHEAD_CUSTOM", look_ahead_custom_blocks=500) == 500


def test_unknown_look_ahead_and_repeated_tools_are_refused() -> None:
    base = build_config().model_dump()["channels"][0]
    with pytest.raises(ConfigError, match="look_ahead"):
        build_config({"channels": [{**base, "look_ahead": "FAST"}]})
    with pytest.raises(ConfigError, match="tool D numbers repeat"):
        build_config({"tools": [{"d": 1, "radius_mm": 1}, {"d": 1, "radius_mm": 2}]})
