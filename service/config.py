"""The service's configuration, loaded: the machine (``machine_config``), the front ends
(``frontend_config``) and the limits (``limits``) in one TOML file.

A TOML file given with ``--config`` is laid over the embedded default: tables merge key
by key, arrays (``channels``, ``physical_axes``, a channel's ``axes``) replace the
default's array whole. ISG parameter lists the file names are read and laid over it too
(``param_list``). Every mistake is refused at start with a message naming the key. The
kernel is handed ``ServiceConfig.machine``, the machine part alone.
"""

from __future__ import annotations

import tomllib
from enum import StrEnum
from pathlib import Path
from typing import Any

from pydantic import Field, ValidationError

from .frontend_config import AdsConfig, SecurityConfig
from .kernel.realtime_priority import DEFAULT_RT_PRIORITY, RT_PRIORITY_MAX
from .limits import LimitsConfig
from .machine_config import EMBEDDED_MACHINES, EmbeddedMachine, MachineConfig, Strict
from .opcua.config import OpcUaConfig
from .param_list import ParamListError, read_axis_list, read_channel_list


class SampleMode(StrEnum):
    """How the notification hub samples subscriptions (``[clock] samples``,
    ``cnc-service --samples``; docs/kernel.md, "Traces that repeat")."""

    LATEST = "latest"  # the kernel never waits for a reader: a reader far behind misses
    # the oldest samples (a sequence gap), the newest go out
    REPEATABLE = "repeatable"  # every due sample goes out: a slow reader slows the kernel;
    # the virtual clocks stand still while the kernel rests; samples carry kernel time


class ClockConfig(Strict):
    """``[clock]``: how kernel time meets the clients."""

    samples: SampleMode = Field(
        SampleMode.LATEST, description="latest: the kernel never waits for a reader (a "
        "reader far behind misses samples); repeatable: every subscription is sampled at "
        "its due cycles of kernel time and nothing is dropped (a slow reader slows the "
        "kernel), virtual and step clocks only (docs/kernel.md, Traces that repeat)",
    )


class ServiceConfig(MachineConfig):
    """The whole TOML file: the machine's keys, and the tables of the front ends, the
    store and the limits beside them."""

    program_store_dir: str | None = Field(
        None, description="directory of the program store; default: programs/ in the data "
        "directory (service/storage/data_location.py)"
    )
    data_dir: str | None = Field(
        None, description="the service's data directory (the program store is its programs/, "
        "the output area its output/); default: cnc-data in the working directory at start"
    )
    output_dir: str | None = Field(
        None, description="directory of the output area (the files the kernel writes); "
        "default: output/ in the data directory, else <program store>-output beside the "
        "store (service/storage/data_location.py)"
    )
    rt_priority: int = Field(
        DEFAULT_RT_PRIORITY, ge=0, le=RT_PRIORITY_MAX,
        description="realtime clock: SCHED_FIFO priority (1..99) of the cycle thread, with the "
        "service's memory locked, where the process is permitted (root, CAP_SYS_NICE); 0: a "
        "normal thread (docs/kernel.md)",
    )
    clock: ClockConfig = Field(
        default_factory=ClockConfig, description="[clock]: how subscriptions are sampled "
        "(samples = latest | repeatable)",
    )
    ads: AdsConfig = Field(
        default_factory=AdsConfig, description="the ADS front end ([ads] endpoint, net_id, routes)"
    )
    opcua: OpcUaConfig = Field(
        default_factory=OpcUaConfig,
        description="the OPC UA front end ([opcua] endpoint, loopback_role; docs/opcua.md)",
    )
    limits: LimitsConfig = Field(
        default_factory=LimitsConfig,
        description="what one client may cost the service ([limits]; docs/limits.md)",
    )
    security: SecurityConfig = Field(
        default_factory=SecurityConfig, description="CURVE keys and allow-list ([security])"
    )

    @property
    def machine(self) -> MachineConfig:
        """The machine part alone: what the kernel is given."""
        return MachineConfig.model_construct(
            **{name: getattr(self, name) for name in MachineConfig.model_fields})


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
    overrides: dict[str, Any] | None = None, source: str = "config", base_dir: Path | None = None,
    machine: EmbeddedMachine = EmbeddedMachine.THREE_AXIS,
) -> ServiceConfig:
    """The embedded ``machine`` (``EMBEDDED_MACHINES``; the default machine) with
    ``overrides`` laid over it, validated. Parameter lists the overrides name are read
    relative to ``base_dir`` (default: the working directory)."""
    merged = _merge(EMBEDDED_MACHINES[EmbeddedMachine(machine)], overrides or {})
    if "axis_parameter_lists" in merged or any(
        isinstance(c, dict) and "parameter_list" in c for c in merged.get("channels", [])
    ):
        merged = _apply_parameter_lists(merged, base_dir or Path.cwd())
    try:
        return ServiceConfig.model_validate(merged)
    except ValidationError as exc:
        raise _explain(exc, source) from None


def load_config(path: Path | None,
                machine: EmbeddedMachine = EmbeddedMachine.THREE_AXIS) -> ServiceConfig:
    """Read ``path`` (TOML) over the embedded ``machine``; that machine alone when None."""
    if path is None:
        return build_config(machine=machine)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read: {exc.strerror}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None
    return build_config(data, str(path), path.parent, machine)
