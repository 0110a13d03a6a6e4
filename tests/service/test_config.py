"""Configuration: the embedded default machine, overrides, and errors that name the key."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from cnc_objects.service.config import ConfigError, build_config, load_config


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
    assert blocks(interpolator_function="FCT_LOOK_AHEAD_LOW") == 30
    assert blocks(interpolator_function="FCT_LOOK_AHEAD_HIGH | FCT_CONTOUR_LAH") == 190
    assert blocks(interpolator_function="FCT_IPO_DEFAULT") == 120
    assert blocks(interpolator_function="FCT_LOOK_AHEAD_CUSTOM",
                  look_ahead_custom_blocks=500) == 500


def test_contour_lookahead_is_an_interpolator_function() -> None:
    config = build_config()
    assert config.channels[0].contour_lookahead  # the default machine's channel 1 has it
    assert not config.channels[1].contour_lookahead
    assert config.channels[0].contour_lookahead_log_max == 128  # P-CHAN-00658 default
    base = config.model_dump()["channels"][1]
    changed = build_config({"channels": [config.model_dump()["channels"][0], {
        **base, "interpolator_function": "fct_ipo_default,FCT_CONTOUR_LAH",
        "contour_lookahead_log_max": 0}]})
    assert changed.channels[1].contour_lookahead
    assert changed.channels[1].contour_lookahead_log_max == 0


@pytest.mark.parametrize(("value", "message"), [
    ("FAST", "unknown interpolator function 'FAST'"),
    ("FCT_SYNC", "FCT_SYNC is not supported by this kernel"),
    ("FCT_LOOK_AHEAD_LOW | FCT_LOOK_AHEAD_HIGH",
     "choose one look-ahead size, not FCT_LOOK_AHEAD_HIGH and FCT_LOOK_AHEAD_LOW"),
])
def test_bad_interpolator_functions_are_refused(value: str, message: str) -> None:
    base = build_config().model_dump()["channels"][0]
    with pytest.raises(ConfigError) as caught:
        build_config({"channels": [{**base, "interpolator_function": value}]})
    assert "channels.0.interpolator_function" in str(caught.value)
    assert message in str(caught.value)


def test_repeated_tools_are_refused() -> None:
    with pytest.raises(ConfigError, match="tool D numbers repeat"):
        build_config({"tools": [{"d": 1, "radius_mm": 1}, {"d": 1, "radius_mm": 2}]})


def test_data_directory_keys(tmp_path: Path) -> None:
    path = tmp_path / "machine.toml"
    path.write_text('data_dir = "~/mill-1"\nprogram_store_dir = "/srv/programs"\n')
    config = load_config(path)
    assert config.data_dir == "~/mill-1" and config.program_store_dir == "/srv/programs"
    assert build_config().data_dir is None  # the service's default: ./cnc-data
    with pytest.raises(ConfigError, match="data_dir: Input should be a valid string"):
        build_config({"data_dir": 5})


# ------------------------------------------------------------------ parameter lists

PARAMS = Path(__file__).parent.parent / "data" / "params"


def _toml(tmp_path: Path, text: str) -> Path:
    for name in ("axis-1.lis", "axis-11.lis", "channel-2.lis", "axis-bad.lis"):
        shutil.copy(PARAMS / name, tmp_path / name)
    for number in (12, 13):
        (tmp_path / f"axis-{number}.lis").write_text(
            f"kopf.achs_nr {number}\nkopf.clone_of {number - 10}\n"
        )
    path = tmp_path / "machine.toml"
    path.write_text(text)
    return path


JOG_CHANNEL = '[[channels]]\nid = 2\nname = "jog"\nparameter_list = "channel-2.lis"\n'
MAIN_CHANNEL = (
    '[[channels]]\nid = 1\nname = "main"\naxes = [{name = "X", logical_number = 1},'
    ' {name = "Y", logical_number = 2}, {name = "Z", logical_number = 3}]\n'
)


def test_parameter_lists_give_channel_axes_and_axis_parameters(tmp_path: Path) -> None:
    path = _toml(tmp_path, 'axis_parameter_lists = ["axis-1.lis", "axis-11.lis",'
                 ' "axis-12.lis", "axis-13.lis"]\n' + MAIN_CHANNEL + JOG_CHANNEL)
    config = load_config(path)
    jog = config.channels[1]
    assert jog.jog_of_path_only
    assert [(a.name, a.logical_number) for a in jog.axes] == [("X", 11), ("Y", 12), ("Z", 13)]
    clone = jog.axes[0]
    assert (clone.link_to, clone.clone_of, clone.auto_release_of_axis_link) == (1, 1, True)
    assert clone.limits.vel_max_mm_s == 250.0
    assert "limits" in clone.model_fields_set  # written: the clone overrides only this
    assert clone.limits.model_fields_set == {"vel_max_mm_s"}
    # Axis 12's list writes no link_to: it follows its master, axis 2, to drive 2.
    assert jog.axes[1].link_to is None and jog.axes[1].clone_of == 2
    assert config.link_of(12) == 2 and config.link_of(11) == 1


def test_parameter_list_problems_name_file_and_line(tmp_path: Path) -> None:
    path = _toml(tmp_path, 'axis_parameter_lists = ["axis-bad.lis"]\n')
    with pytest.raises(ConfigError) as caught:
        load_config(path)
    assert f"{tmp_path / 'axis-bad.lis'}:" in str(caught.value)
    (tmp_path / "axis-42.lis").write_text("kopf.achs_nr 42\n")
    path = _toml(tmp_path, 'axis_parameter_lists = ["axis-42.lis"]\n')
    with pytest.raises(ConfigError, match="kopf.achs_nr 42 is not an axis of any channel"):
        load_config(path)
    path = _toml(tmp_path, JOG_CHANNEL + 'axes = [{name = "X", logical_number = 11}]\n')
    with pytest.raises(ConfigError, match="axes are given twice"):
        load_config(path)
    path = _toml(tmp_path, '[[channels]]\nid = 2\nname = "j"\nparameter_list = "none.lis"\n')
    with pytest.raises(ConfigError, match="none.lis"):
        load_config(path)


def test_link_to_defaults_to_the_own_drive_or_the_masters() -> None:
    config = build_config({"channels": [
        {"id": 1, "name": "a", "axes": [{"name": "X", "logical_number": 1}]},
        {"id": 2, "name": "b", "axes": [{"name": "X", "logical_number": 11, "clone_of": 1}]},
    ]})
    assert config.link_of(1) == 1 and config.link_of(11) == 1
    with pytest.raises(ConfigError, match="no physical axis 7"):
        build_config({"channels": [
            {"id": 1, "name": "a", "axes": [{"name": "X", "logical_number": 7}]}]})


# --------------------------------------------------------------------------- [ads]


def test_ads_defaults() -> None:
    ads = build_config().ads
    assert ads.endpoint == "127.0.0.1:48898" and ads.address == ("127.0.0.1", 48898)
    assert ads.net_id is None and ads.routes == () and ads.max_frame_bytes == 1 << 20


def test_ads_table_from_toml(tmp_path: Path) -> None:
    path = tmp_path / "machine.toml"
    path.write_text(
        '[ads]\nendpoint = "0.0.0.0"\nnet_id = "192.0.2.2.1.1"\nmax_frame_bytes = 65536\n'
        '[[ads.routes]]\nname = "hmi"\nnet_id = "192.0.2.7.1.1"\naddress = "192.0.2.7"\n'
        '[[ads.routes]]\nname = "v6"\nnet_id = "10.0.0.1.1.1"\naddress = "2001:db8::0:1"\n'
    )
    ads = load_config(path).ads
    assert ads.address == ("0.0.0.0", 48898) and ads.net_id == "192.0.2.2.1.1"
    assert ads.max_frame_bytes == 65536
    assert [(r.name, r.net_id, r.address) for r in ads.routes] == [
        ("hmi", "192.0.2.7.1.1", "192.0.2.7"), ("v6", "10.0.0.1.1.1", "2001:db8::1")]
    assert build_config({"ads": {"endpoint": "off"}}).ads.address is None
    assert build_config({"ads": {"endpoint": "[::1]:4000"}}).ads.address == ("::1", 4000)


@pytest.mark.parametrize(
    ("ads", "message"),
    [
        ({"endpoint": "host:port"}, "ads.endpoint: 'host:port': the port must be a number"),
        ({"endpoint": ":48898"}, "ads.endpoint: ':48898': the host is missing"),
        ({"net_id": "1.2.3"}, "ads.net_id: '1.2.3' is not an AMS Net ID"),
        ({"routes": [{"name": "a", "net_id": "1.2.3.4.1.1", "address": "nowhere"}]},
         "ads.routes.0.address: 'nowhere' is not an IP address"),
        ({"routes": [{"name": "a", "net_id": "1.2.3.4.1", "address": "192.0.2.7"}]},
         "ads.routes.0.net_id"),
        ({"routes": [{"net_id": "1.2.3.4.1.1", "address": "192.0.2.7"}]}, "ads.routes.0.name"),
        ({"max_frame_bytes": 10}, "ads.max_frame_bytes"),
        ({"port": 48898}, "ads.port"),
    ],
)
def test_bad_ads_settings_name_the_key(ads: dict, message: str) -> None:
    with pytest.raises(ConfigError) as caught:
        build_config({"ads": ads}, "machine.toml")
    assert message in str(caught.value)
