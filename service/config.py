"""Machine configuration: pydantic models, the embedded default machine, TOML loading.

A TOML file given with ``--config`` is laid over the embedded default: tables merge key
by key, arrays (``channels``, ``physical_axes``, a channel's ``axes``) replace the
default's array whole. Every mistake is refused at start with a message naming the key.
"""

from __future__ import annotations

import ipaddress
import tomllib
from enum import StrEnum
from pathlib import Path
from typing import Any, Literal

from pydantic import (
    AliasChoices, BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator,
)

from cnc_objects.protocol.ams import parse_net_id
from cnc_objects.protocol.constants import AMS_MAX_FRAME_BYTES, AMS_TCP_PORT

from .limits import LimitsConfig
from .param_list import ParamListError, read_axis_list, read_channel_list


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class AxisLimits(_Strict):
    """Limits the planner and the position controller respect for one axis."""

    vel_max_mm_s: float = Field(500.0, gt=0, description="maximum axis velocity (mm/s)")
    acc_max_mm_s2: float = Field(5000.0, gt=0, description="maximum acceleration (mm/s^2)")
    sw_limit_min_mm: float = Field(-1000.0, description="negative software limit (mm)")
    sw_limit_max_mm: float = Field(1000.0, description="positive software limit (mm)")
    vel_jump_mm_s: float = Field(
        20.0, ge=0, description="permitted velocity jump of the axis at a block junction (mm/s)"
    )

    @model_validator(mode="after")
    def _limits_ordered(self) -> AxisLimits:
        if self.sw_limit_min_mm >= self.sw_limit_max_mm:
            raise ValueError("sw_limit_min_mm must be below sw_limit_max_mm")
        return self


class PhysicalAxisConfig(_Strict):
    """A drive of the platform."""

    number: int = Field(ge=1, le=0xFFFF, description="physical axis number (link target)")
    name: str = Field(min_length=1, max_length=15)


class AxisConfig(_Strict):
    """A logical axis of a channel: its name there and its axis parameter list.

    A clone (``clone_of``) takes every parameter of its master when the kernel
    initialises the axes and overrides only what is written here: which fields were
    written is kept by pydantic (``model_fields_set``), so leave out what the clone
    should inherit. ``link_to`` left out means the drive with the axis's own number
    (or, for a clone, the master's drive).
    """

    name: str = Field(min_length=1, max_length=15, description="axis name in the channel")
    logical_number: int = Field(ge=1, le=0xFFFF, description="kopf.achs_nr (P-AXIS-00016)")
    link_to: int | None = Field(None, ge=1, le=0xFFFF, description="kopf.link_to (P-AXIS-00101)")
    clone_of: int | None = Field(
        None, ge=1, le=0xFFFE, description="kopf.clone_of (P-AXIS-00040)"
    )
    axis_type: Literal["linear"] = Field("linear", description="kenngr.achs_typ (P-AXIS-00018)")
    auto_release_of_axis_link: bool = Field(
        False, description="kenngr.auto_release_of_axis_link (P-AXIS-00483)"
    )
    limits: AxisLimits = AxisLimits()


class InterpolatorFunction(StrEnum):
    """Identifiers of the interpolator functions (P-CHAN-00650) this kernel implements."""

    IPO_DEFAULT = "FCT_IPO_DEFAULT"  # = FCT_LOOK_AHEAD_STANDARD
    LOOK_AHEAD_LOW = "FCT_LOOK_AHEAD_LOW"  # 30 blocks
    LOOK_AHEAD_STANDARD = "FCT_LOOK_AHEAD_STANDARD"  # 120 blocks
    LOOK_AHEAD_HIGH = "FCT_LOOK_AHEAD_HIGH"  # 190 blocks
    LOOK_AHEAD_CUSTOM = "FCT_LOOK_AHEAD_CUSTOM"  # look_ahead_custom_blocks (P-CHAN-00653)
    CONTOUR_LAH = "FCT_CONTOUR_LAH"  # contour look-ahead (FCT-C40)


LOOK_AHEAD_BLOCKS = {
    InterpolatorFunction.IPO_DEFAULT: 120,
    InterpolatorFunction.LOOK_AHEAD_LOW: 30,
    InterpolatorFunction.LOOK_AHEAD_STANDARD: 120,
    InterpolatorFunction.LOOK_AHEAD_HIGH: 190,
}
_LOOK_AHEAD_SIZES = frozenset(LOOK_AHEAD_BLOCKS) | {InterpolatorFunction.LOOK_AHEAD_CUSTOM}
# ISG identifiers of functions this kernel does not have: named as such when configured
_NOT_SUPPORTED_FUNCTIONS = frozenset({
    "FCT_SYNC", "FCT_LOOK_AHEAD_OPT", "FCT_LIFT_UP_TIME", "FCT_SHIFT_NCBL",
    "FCT_CALC_STATE_AT_T", "FCT_CALC_TIME", "FCT_DYN_POS_LIMIT", "FCT_EXTENSION_EQUIDIST",
})


def parse_interpolator_functions(text: str) -> frozenset[InterpolatorFunction]:
    """The functions of a P-CHAN-00650 value such as ``FCT_IPO_DEFAULT | FCT_CONTOUR_LAH``
    (identifiers separated by ``|``, commas or blanks); ValueError names what is wrong.
    At most one look-ahead size; none means FCT_IPO_DEFAULT."""
    words = [w for w in text.replace("|", " ").replace(",", " ").split() if w]
    found: set[InterpolatorFunction] = set()
    for word in words:
        upper = word.upper()
        if upper in _NOT_SUPPORTED_FUNCTIONS:
            raise ValueError(f"{upper} is not supported by this kernel")
        try:
            found.add(InterpolatorFunction(upper))
        except ValueError:
            known = ", ".join(f.value for f in InterpolatorFunction)
            raise ValueError(f"unknown interpolator function {word!r} (known: {known})") from None
    sizes = sorted(f.value for f in found & _LOOK_AHEAD_SIZES)
    if len(sizes) > 1:
        raise ValueError(f"choose one look-ahead size, not {' and '.join(sizes)}")
    if not sizes:
        found.add(InterpolatorFunction.IPO_DEFAULT)
    return frozenset(found)


class ToolConfig(_Strict):
    """One entry of the tool table: D number and radius."""

    d: int = Field(ge=1, le=9999, description="tool offset number (D word)")
    radius_mm: float = Field(ge=0, description="tool radius (mm)")


class SyntaxCheckConfig(_Strict):
    """Channel parameters of the syntax check (FCT-C9), ``syn_chk.*``; ISG's spellings
    before V2.11.2012.07 (``fehler_gesamt``, ``fehler_pro_zeile``) are accepted too."""

    errors_total: int = Field(
        0, ge=0, le=0xFFFF, validation_alias=AliasChoices("errors_total", "fehler_gesamt"),
        description="P-CHAN-00019: the check ends after this many errors (0: no limit)",
    )
    errors_per_block: int = Field(
        0, ge=0, le=0xFFFF,
        validation_alias=AliasChoices("errors_per_block", "fehler_pro_zeile"),
        description="P-CHAN-00020: after this many errors in one NC line the check goes on "
        "with the next line (0: no limit)",
    )
    interactive: bool = Field(
        False, description="P-CHAN-00028: stop after each error and wait for START or RESET"
    )
    record_result: bool = Field(
        False, description="P-CHAN-00416: write every checked line and error to dec0<c>.sc"
    )


class HscsModeConfig(_Strict):
    """One mode of the high-speed settings (SysHscSettings): ``hscs.<mode>.*``."""

    prog: str = Field("", max_length=83, description="program the cycle calls (L <prog>)")
    tolerance: int = Field(
        0, ge=0, le=0x7FFFFFFF,
        description="machining tolerance in 0.1 um; NC programs read it in mm as "
        "V.G.HSCS.<MODE>.TOLERANCE",
    )


def _hscs_default(mode: str, tolerance: int) -> HscsModeConfig:
    return HscsModeConfig(prog=f"manufacturerHsc{mode}Settings.nc", tolerance=tolerance)


class HscsConfig(_Strict):
    """Channel parameters of the SysHscSettings cycle (``hscs.<mode>.prog/.tolerance``).
    The defaults name the example programs of the cycle documentation (docs/examples/hsc)."""

    deselect: HscsModeConfig = Field(default_factory=lambda: _hscs_default("Deselect", 0))
    rough: HscsModeConfig = Field(default_factory=lambda: _hscs_default("Rough", 1000))
    prefinish: HscsModeConfig = Field(default_factory=lambda: _hscs_default("Prefinish", 500))
    finish: HscsModeConfig = Field(default_factory=lambda: _hscs_default("Finish", 100))


class EnhancedLookAheadConfig(_Strict):
    """Defaults of the enhanced look-ahead parameters (MTC200 names), ``la.*``; a
    program changes them with ``METB=``, ``VFBT=``, ``BBTRC=`` (docs/lookahead.md)."""

    metb_s: float = Field(
        0.010, gt=0, le=10.0,
        description="METB: shortest execution time of a sub-block the section planner "
        "creates (s); must exceed the cycle time",
    )
    vfbt: float = Field(
        1.0, gt=0, le=1.0,
        description="VFBT: factor on the permitted speed at non-tangential block transitions",
    )
    bbtrc: int = Field(
        8, ge=1, le=1000,
        description="BBTRC: blocks the bottleneck check of the tool radius compensation "
        "compares each compensated block with",
    )


class ChannelConfig(_Strict):
    """A channel and its axes."""

    id: int = Field(ge=1, le=0xFF, description="logical channel id (CID)")
    name: str = Field(min_length=1, max_length=31)
    axes: tuple[AxisConfig, ...] = Field(min_length=1, max_length=32)
    jog_of_path_only: bool = Field(False, description="P-CHAN-00306")
    suspend_output_at_start: bool = Field(
        False, description="start with axis output suspended (the channel holds no axes)"
    )
    feed_override_max: int = Field(
        1000, ge=0, le=0xFFFF, description="largest accepted feed override (0.1 %)"
    )
    interpolator_function: str = Field(
        "FCT_IPO_DEFAULT",
        description="P-CHAN-00650: interpolator functions, e.g. 'FCT_IPO_DEFAULT | "
        "FCT_CONTOUR_LAH' (look-ahead size and functions such as contour look-ahead)",
    )
    look_ahead_custom_blocks: int = Field(
        120, ge=2, le=10_000, description="P-CHAN-00653: buffer size with FCT_LOOK_AHEAD_CUSTOM"
    )
    contour_lookahead_log_max: int = Field(
        128, ge=0, le=0xFFFFFFFE,
        description="P-CHAN-00658: contour elements the contour look-ahead log keeps",
    )
    syn_chk: SyntaxCheckConfig = Field(
        default_factory=SyntaxCheckConfig, description="syntax check (P-CHAN-00019/20/28/416)"
    )
    hscs: HscsConfig = Field(
        default_factory=HscsConfig, description="high-speed settings cycle (hscs.*)"
    )
    la: EnhancedLookAheadConfig = Field(
        default_factory=EnhancedLookAheadConfig,
        description="enhanced look-ahead defaults (LA_ON/LA_OFF; METB, VFBT, BBTRC)",
    )

    @field_validator("interpolator_function")
    @classmethod
    def _known_functions(cls, value: str) -> str:
        parse_interpolator_functions(value)
        return value

    @property
    def interpolator_functions(self) -> frozenset[InterpolatorFunction]:
        """The functions of ``interpolator_function``."""
        return parse_interpolator_functions(self.interpolator_function)

    @property
    def look_ahead_blocks(self) -> int:
        """Blocks the look-ahead buffer holds."""
        functions = self.interpolator_functions
        for function, blocks in LOOK_AHEAD_BLOCKS.items():
            if function in functions:
                return blocks
        return self.look_ahead_custom_blocks

    @property
    def contour_lookahead(self) -> bool:
        """FCT_CONTOUR_LAH is enabled: #CONTOUR LOOKAHEAD and the control unit work."""
        return InterpolatorFunction.CONTOUR_LAH in self.interpolator_functions

    @model_validator(mode="after")
    def _unique_axis_names(self) -> ChannelConfig:
        names = [a.name for a in self.axes]
        if len(set(names)) != len(names):
            raise ValueError(f"axis names repeat in channel {self.id}: {names}")
        return self


def parse_ads_endpoint(text: str) -> tuple[str, int] | None:
    """``HOST[:PORT]`` of the ADS listener as (host, port), port 48898 when left out;
    None for ``off``. IPv6 hosts in brackets (``[::1]:48898``). Port 0 takes any free
    port. ``ValueError`` says what is wrong."""
    text = text.strip()
    if text.lower() == "off":
        return None
    port_text = ""
    if text.startswith("["):
        host, sep, rest = text[1:].partition("]")
        if not sep or (rest and not rest.startswith(":")):
            raise ValueError(f"{text!r}: write an IPv6 host as [addr] or [addr]:port")
        port_text = rest[1:]
    else:
        host, _, port_text = text.partition(":")
        if ":" in port_text:
            raise ValueError(f"{text!r}: write an IPv6 host in brackets, [addr]:port")
    if not host:
        raise ValueError(f"{text!r}: the host is missing (HOST[:PORT], or off)")
    if not port_text:
        return host, AMS_TCP_PORT
    if not port_text.isdigit() or int(port_text) > 0xFFFF:
        raise ValueError(f"{text!r}: the port must be a number 0..65535")
    return host, int(port_text)


RoleName = Literal["monitor", "operator", "admin"]  # protocol.roles.Role, as written
_Z85_KEY_CHARS = 40  # a CURVE key (32 bytes) in Z85 text
_Z85_ALPHABET = frozenset(
    "0123456789abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ.-:+=^!/*?&<>()[]{}@%$#")


def _checked_net_id(value: str) -> str:
    """An AMS Net ID of the configuration, stripped (``ValueError`` when it is none)."""
    parse_net_id(value)
    return value.strip()


class AdsRouteConfig(_Strict):
    """A route of the ADS front end: a peer that may connect from ``address``."""

    name: str = Field(min_length=1, max_length=63, description="name of the route")
    net_id: str = Field(description="AMS Net ID the peer sends from (a.b.c.d.e.f)")
    address: str = Field(description="IP address the peer connects from")
    role: RoleName = Field(
        "operator",
        description="what the peer may do: monitor, operator or admin (docs/security.md)",
    )

    @field_validator("net_id")
    @classmethod
    def _net_id(cls, value: str) -> str:
        return _checked_net_id(value)

    @field_validator("address")
    @classmethod
    def _address(cls, value: str) -> str:
        try:
            return str(ipaddress.ip_address(value.strip()))
        except ValueError:
            raise ValueError(f"{value!r} is not an IP address") from None


class AdsConfig(_Strict):
    """The ADS front end (AMS/TCP): where it listens, its AMS Net ID, its routes."""

    endpoint: str = Field(
        f"127.0.0.1:{AMS_TCP_PORT}",
        description="HOST[:PORT] to listen on for ADS (AMS/TCP), or off",
    )
    net_id: str | None = Field(
        None, description="AMS Net ID of the service (default: the bound IPv4 address + .1.1)"
    )
    routes: tuple[AdsRouteConfig, ...] = Field(
        (), description="peers served besides loopback (name, net_id, address)"
    )
    max_frame_bytes: int = Field(
        AMS_MAX_FRAME_BYTES, ge=1024, le=64 << 20,
        description="longest AMS/TCP frame a client may send (bytes); longer closes it",
    )
    loopback_role: RoleName | None = Field(
        None, description="role of ADS peers on loopback (default: admin; monitor when the "
        "service runs with keys)"
    )

    @field_validator("endpoint")
    @classmethod
    def _endpoint(cls, value: str) -> str:
        parse_ads_endpoint(value)
        return value.strip()

    @field_validator("net_id")
    @classmethod
    def _net_id(cls, value: str | None) -> str | None:
        return None if value is None else _checked_net_id(value)

    @property
    def address(self) -> tuple[str, int] | None:
        """(host, port) to listen on, None when ADS is off."""
        return parse_ads_endpoint(self.endpoint)


class ClientKeyConfig(_Strict):
    """A client of the allow-list given in the configuration instead of a key file."""

    name: str = Field(min_length=1, max_length=63, description="name of the client (logs)")
    public_key: str = Field(description="the client's CURVE public key, 40 Z85 characters")
    role: RoleName = Field(description="what the client may do: monitor, operator or admin")

    @field_validator("public_key")
    @classmethod
    def _z85_key(cls, value: str) -> str:
        value = value.strip()
        if len(value) != _Z85_KEY_CHARS or not set(value) <= _Z85_ALPHABET:
            raise ValueError(f"must be the {_Z85_KEY_CHARS} Z85 characters of a CURVE public "
                             "key (the public-key line of NAME.key)")
        return value


class SecurityConfig(_Strict):
    """CURVE keys of the ZeroMQ front end (docs/security.md); ``--keys DIR`` beats
    ``keys_dir``. Relative paths are taken from the working directory at start."""

    keys_dir: str | None = Field(
        None, description="directory of server.key_secret and clients/<role>/*.key: CURVE on"
    )
    server_secret_key_file: str | None = Field(
        None, description="the service's secret key file (default: keys_dir/server.key_secret)"
    )
    clients_dir: str | None = Field(
        None, description="allow-list directory clients/<role>/*.key (default: keys_dir/clients)"
    )
    clients: tuple[ClientKeyConfig, ...] = Field(
        (), description="allow-list entries besides the directory's (name, public_key, role)"
    )

    @property
    def curve(self) -> bool:
        """True when the configuration turns CURVE on."""
        return bool(self.keys_dir or self.server_secret_key_file)


class MachineConfig(_Strict):
    """The whole machine: platform axes, channels, cycle time."""

    name: str = Field("cnc-objects", min_length=1, max_length=31)
    cycle_ms: float = Field(1.0, gt=0.05, le=100.0, description="GEO cycle time (ms)")
    physical_axes: tuple[PhysicalAxisConfig, ...] = Field(min_length=1)
    channels: tuple[ChannelConfig, ...] = Field(min_length=1, max_length=12)
    tools: tuple[ToolConfig, ...] = Field((), description="tool table (D number -> radius)")
    program_store_dir: str | None = Field(
        None, description="directory of the program store; default: programs/ in the data "
        "directory (service/data_location.py)"
    )
    data_dir: str | None = Field(
        None, description="the service's data directory (the program store is its programs/, "
        "the output area its output/); default: cnc-data in the working directory at start"
    )
    output_dir: str | None = Field(
        None, description="directory of the output area (the files the kernel writes); "
        "default: output/ in the data directory, else <program store>-output beside the "
        "store (service/data_location.py)"
    )
    ads: AdsConfig = Field(
        default_factory=AdsConfig, description="the ADS front end ([ads] endpoint, net_id, routes)"
    )
    limits: LimitsConfig = Field(
        default_factory=LimitsConfig,
        description="what one client may cost the service ([limits]; docs/limits.md)",
    )
    security: SecurityConfig = Field(
        default_factory=SecurityConfig, description="CURVE keys and allow-list ([security])"
    )

    @model_validator(mode="after")
    def _references_resolve(self) -> MachineConfig:
        physical = [a.number for a in self.physical_axes]
        if len(set(physical)) != len(physical):
            raise ValueError(f"physical axis numbers repeat: {physical}")
        ids = [c.id for c in self.channels]
        if len(set(ids)) != len(ids):
            raise ValueError(f"channel ids repeat: {ids}")
        d_numbers = [t.d for t in self.tools]
        if len(set(d_numbers)) != len(d_numbers):
            raise ValueError(f"tool D numbers repeat: {d_numbers}")
        logical = [a.logical_number for c in self.channels for a in c.axes]
        if len(set(logical)) != len(logical):
            raise ValueError(f"logical axis numbers (kopf.achs_nr) repeat: {logical}")
        for ci, channel in enumerate(self.channels):
            if channel.la.metb_s <= self.cycle_ms / 1000.0:
                raise ValueError(
                    f"channels.{ci}.la.metb_s: METB {channel.la.metb_s:g} s must be greater "
                    f"than the cycle time {self.cycle_ms / 1000.0:g} s"
                )
            for ai, axis in enumerate(channel.axes):
                where = f"channels.{ci}.axes.{ai}"
                if axis.link_to is not None and axis.link_to not in physical:
                    raise ValueError(
                        f"{where}.link_to: physical axis {axis.link_to} does not exist "
                        f"(configured: {physical})"
                    )
                link = self.link_of(axis.logical_number)
                if link not in physical:
                    raise ValueError(
                        f"{where}.link_to: missing, and there is no physical axis {link} "
                        "to link to (the axis's own number, or its master's drive)"
                    )
        return self

    def axis(self, logical_number: int) -> AxisConfig | None:
        """The configured axis with ``logical_number``, or None."""
        for channel in self.channels:
            for axis in channel.axes:
                if axis.logical_number == logical_number:
                    return axis
        return None

    def link_of(self, logical_number: int) -> int:
        """The physical axis a logical axis is linked to (``kopf.link_to``): written, or
        inherited from the master of a clone, or else the axis's own number."""
        seen: set[int] = set()
        axis = self.axis(logical_number)
        while axis is not None and axis.link_to is None and axis.clone_of is not None:
            master = self.axis(axis.clone_of)
            if master is None or axis.logical_number in seen:  # no master, or a ring
                break
            seen.add(axis.logical_number)
            axis = master
        if axis is None:
            return logical_number
        return axis.link_to if axis.link_to is not None else axis.logical_number

    def startup_axes(self) -> list[tuple[int, AxisConfig]]:
        """Every logical axis in start-up order (channel by channel, axis by axis),
        with the index of its channel: the order the kernel initialises them in."""
        return [(ci, axis) for ci, c in enumerate(self.channels) for axis in c.axes]


DEFAULT_MACHINE: dict[str, Any] = {
    "name": "cnc-objects",
    "cycle_ms": 1.0,
    "tools": [
        {"d": 1, "radius_mm": 1.0},
        {"d": 2, "radius_mm": 2.5},
        {"d": 3, "radius_mm": 5.0},
        {"d": 8, "radius_mm": 4.0},  # the tools of the cycle documentation's examples
        {"d": 9, "radius_mm": 3.0},
    ],
    "physical_axes": [
        {"number": 1, "name": "X"},
        {"number": 2, "name": "Y"},
        {"number": 3, "name": "Z"},
    ],
    "channels": [
        {
            "id": 1,
            "name": "main",
            "interpolator_function": "FCT_IPO_DEFAULT | FCT_CONTOUR_LAH",
            "axes": [
                {"name": "X", "logical_number": 1, "link_to": 1},
                {"name": "Y", "logical_number": 2, "link_to": 2},
                {"name": "Z", "logical_number": 3, "link_to": 3},
            ],
        },
        {
            "id": 2,
            "name": "jog-of-path",
            "jog_of_path_only": True,
            "suspend_output_at_start": True,
            "axes": [
                {"name": "X", "logical_number": 11, "link_to": 1, "clone_of": 1},
                {"name": "Y", "logical_number": 12, "link_to": 2, "clone_of": 2},
                {"name": "Z", "logical_number": 13, "link_to": 3, "clone_of": 3},
            ],
        },
    ],
}


class ConfigError(ValueError):
    """A configuration that cannot be used; the message names the key."""


def _merge(base: dict[str, Any], over: dict[str, Any]) -> dict[str, Any]:
    merged = dict(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(merged.get(key), dict):
            merged[key] = _merge(merged[key], value)
        else:
            merged[key] = value
    return merged


def _explain(exc: ValidationError, source: str) -> ConfigError:
    lines = []
    for err in exc.errors():
        key = ".".join(str(p) for p in err["loc"])
        msg = err["msg"].removeprefix("Value error, ")
        lines.append(f"{source}: {key}: {msg}" if key else f"{source}: {msg}")
    return ConfigError("\n".join(lines))


def _apply_parameter_lists(data: dict[str, Any], base_dir: Path) -> dict[str, Any]:
    """Read the ISG parameter lists the configuration names and lay them over it.

    ``channels[i].parameter_list`` (a channel list) gives that channel's axes,
    ``jog_of_path_only`` and ``syn_chk.*``; ``axis_parameter_lists`` (axis lists) give the parameters of
    the axes whose ``kopf.achs_nr`` they carry. Paths are relative to ``base_dir``.
    """
    data = dict(data)
    channels = [dict(c) for c in data.get("channels", [])]
    problems: list[str] = []
    for ci, channel in enumerate(channels):
        name = channel.pop("parameter_list", None)
        if name is None:
            continue
        try:
            listed = read_channel_list(base_dir / name)
        except ParamListError as exc:
            problems.append(str(exc))
            continue
        if "axes" in listed and "axes" in channel:  # arrays replace: the user wrote both
            problems.append(f"channels.{ci}: axes are given twice, here and in {name}")
            continue
        if "syn_chk" in listed:  # the list's syn_chk keys complete those of the TOML
            channel["syn_chk"] = {**channel.get("syn_chk", {}), **listed.pop("syn_chk")}
        if "hscs" in listed:  # so do its hscs.<mode>.* keys
            hscs = channel.get("hscs", {})
            for mode, values in listed.pop("hscs").items():
                hscs[mode] = {**hscs.get(mode, {}), **values}
            channel["hscs"] = hscs
        channel.update(listed)
    axis_lists = data.pop("axis_parameter_lists", [])
    if not isinstance(axis_lists, list):
        problems.append("axis_parameter_lists: must be a list of file names")
        axis_lists = []
    for name in axis_lists:
        try:
            listed = read_axis_list(base_dir / str(name))
        except ParamListError as exc:
            problems.append(str(exc))
            continue
        number = listed["logical_number"]
        target = [
            (ci, ai)
            for ci, c in enumerate(channels)
            for ai, a in enumerate(c.get("axes") or [])
            if isinstance(a, dict) and a.get("logical_number") == number
        ]
        if not target:
            problems.append(
                f"{base_dir / str(name)}: kopf.achs_nr {number} is not an axis of any channel"
            )
            continue
        ci, ai = target[0]
        axes = [dict(a) for a in channels[ci]["axes"]]
        limits = {**axes[ai].get("limits", {}), **listed.get("limits", {})}
        axes[ai].update(listed)
        if limits:
            axes[ai]["limits"] = limits
        channels[ci]["axes"] = axes
    if problems:
        raise ConfigError("\n".join(problems))
    if channels:
        data["channels"] = channels
    return data


def build_config(
    overrides: dict[str, Any] | None = None, source: str = "config", base_dir: Path | None = None
) -> MachineConfig:
    """The default machine with ``overrides`` laid over it, validated. Parameter lists
    the overrides name are read relative to ``base_dir`` (default: the working
    directory)."""
    merged = _merge(DEFAULT_MACHINE, overrides or {})
    if "axis_parameter_lists" in merged or any(
        isinstance(c, dict) and "parameter_list" in c for c in merged.get("channels", [])
    ):
        merged = _apply_parameter_lists(merged, base_dir or Path.cwd())
    try:
        return MachineConfig.model_validate(merged)
    except ValidationError as exc:
        raise _explain(exc, source) from None


def load_config(path: Path | None) -> MachineConfig:
    """Read ``path`` (TOML) over the default machine; the default alone when None."""
    if path is None:
        return build_config()
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read: {exc.strerror}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None
    return build_config(data, str(path), path.parent)
