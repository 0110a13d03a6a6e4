"""Machine configuration: pydantic models, the embedded default machine, TOML loading.

A TOML file given with ``--config`` is laid over the embedded default: tables merge key
by key, arrays (``channels``, ``physical_axes``, a channel's ``axes``) replace the
default's array whole. Every mistake is refused at start with a message naming the key.
"""

from __future__ import annotations

import tomllib
from enum import StrEnum
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator


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
    """A logical axis of a channel (ISG axis parameter list, ``kopf.*``)."""

    name: str = Field(min_length=1, max_length=15, description="axis name in the channel")
    logical_number: int = Field(ge=1, le=0xFFFF, description="kopf.achs_nr")
    link_to: int = Field(ge=1, le=0xFFFF, description="kopf.link_to (P-AXIS-00101)")
    clone_of: int | None = Field(None, ge=1, description="kopf.clone_of (P-AXIS-00040)")
    limits: AxisLimits = AxisLimits()


class LookAhead(StrEnum):
    """Look-ahead buffer size of a channel (P-CHAN-00650 interpolator functions)."""

    LOW = "FCT_LOOK_AHEAD_LOW"  # 30 blocks
    STANDARD = "FCT_LOOK_AHEAD_STANDARD"  # 120 blocks (default)
    HIGH = "FCT_LOOK_AHEAD_HIGH"  # 190 blocks
    CUSTOM = "FCT_LOOK_AHEAD_CUSTOM"  # look_ahead_custom_blocks (P-CHAN-00653)


LOOK_AHEAD_BLOCKS = {LookAhead.LOW: 30, LookAhead.STANDARD: 120, LookAhead.HIGH: 190}


class ToolConfig(_Strict):
    """One entry of the tool table: D number and radius."""

    d: int = Field(ge=1, le=9999, description="tool offset number (D word)")
    radius_mm: float = Field(ge=0, description="tool radius (mm)")


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
    look_ahead: LookAhead = Field(LookAhead.STANDARD, description="P-CHAN-00650")
    look_ahead_custom_blocks: int = Field(
        120, ge=2, le=10_000, description="P-CHAN-00653: buffer size with FCT_LOOK_AHEAD_CUSTOM"
    )

    @property
    def look_ahead_blocks(self) -> int:
        """Blocks the look-ahead buffer holds."""
        return LOOK_AHEAD_BLOCKS.get(self.look_ahead, self.look_ahead_custom_blocks)

    @model_validator(mode="after")
    def _unique_axis_names(self) -> ChannelConfig:
        names = [a.name for a in self.axes]
        if len(set(names)) != len(names):
            raise ValueError(f"axis names repeat in channel {self.id}: {names}")
        return self


class MachineConfig(_Strict):
    """The whole machine: platform axes, channels, cycle time."""

    name: str = Field("cnc-objects", min_length=1, max_length=31)
    cycle_ms: float = Field(1.0, gt=0.05, le=100.0, description="GEO cycle time (ms)")
    physical_axes: tuple[PhysicalAxisConfig, ...] = Field(min_length=1)
    channels: tuple[ChannelConfig, ...] = Field(min_length=1, max_length=12)
    tools: tuple[ToolConfig, ...] = Field((), description="tool table (D number -> radius)")
    program_store_dir: str | None = Field(
        None, description="directory of the program store; default: per-user data directory"
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
            for ai, axis in enumerate(channel.axes):
                where = f"channels.{ci}.axes.{ai}"
                if axis.link_to not in physical:
                    raise ValueError(
                        f"{where}.link_to: physical axis {axis.link_to} does not exist "
                        f"(configured: {physical})"
                    )
        return self


DEFAULT_MACHINE: dict[str, Any] = {
    "name": "cnc-objects",
    "cycle_ms": 1.0,
    "tools": [
        {"d": 1, "radius_mm": 1.0},
        {"d": 2, "radius_mm": 2.5},
        {"d": 3, "radius_mm": 5.0},
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


def build_config(overrides: dict[str, Any] | None = None, source: str = "config") -> MachineConfig:
    """The default machine with ``overrides`` laid over it, validated."""
    try:
        return MachineConfig.model_validate(_merge(DEFAULT_MACHINE, overrides or {}))
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
    return build_config(data, str(path))
