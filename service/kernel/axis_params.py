"""Axis parameters as the kernel uses them, with clones resolved once at initialisation.

The configuration holds each axis's parameter list as written. ``initialise_axes``
turns them into the effective parameters, axis by axis in start-up order (channel by
channel, axis by axis), the way the ISG kernel initialises its axes (FCT-C15, P-AXIS-00040):

- a clone (``kopf.clone_of``) copies every parameter of its master, then overrides what
  its own list writes. The master must exist and be initialised already, that is, come
  earlier in start-up order; otherwise errors 70172 and 50462 are reported and the axis
  is created from its own list alone, without cloning;
- the copy is taken once: ``update_axis`` changes one axis later and never reaches its
  clones, and the clone reference itself cannot change after the first initialisation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from enum import IntEnum
from typing import Any

from ..machine_config import AxisConfig, AxisLimits, MachineConfig


class AxisErrorId(IntEnum):
    """Ids of the messages axis initialisation and the jog-of-path check give."""

    CLONE_MASTER_MISSING = 70172  # ISG: the master axis of a clone does not exist
    CLONE_NOT_CREATED = 50462  # ISG: the clone is created without a cloning process
    JOG_OF_PATH_AXIS_NOT_CLONE = 70900  # project: P-CHAN-00306 check failed for an axis
    CLONE_LIMITS_INCONSISTENT = 70901  # project: the clone's limits contradict its master's


@dataclass(frozen=True, slots=True)
class AxisParameters:
    """The effective parameters of one logical axis."""

    logical_number: int
    link_to: int
    clone_of: int | None  # the configured clone reference; fixed after initialisation
    cloned: bool  # True when the parameters were copied from the master
    auto_release_of_axis_link: bool
    vel_max_mm_s: float
    acc_max_mm_s2: float
    vel_jump_mm_s: float
    sw_limit_min_mm: float
    sw_limit_max_mm: float
    sw_limit_check: int  # P-AXIS-00705: -1 once referenced, 0 never, 1 always


@dataclass(frozen=True, slots=True)
class AxisMessage:
    """A message of axis initialisation, for the error list of the axis's channel."""

    id: int
    text: str
    channel_index: int
    warning: bool = True


_LIMIT_FIELDS = tuple(AxisLimits.model_fields)


def _own(axis: AxisConfig, link_to: int) -> AxisParameters:
    limits = axis.limits
    return AxisParameters(
        logical_number=axis.logical_number,
        link_to=link_to,
        clone_of=axis.clone_of,
        cloned=False,
        auto_release_of_axis_link=axis.auto_release_of_axis_link,
        **{name: getattr(limits, name) for name in _LIMIT_FIELDS},
    )


def _cloned(axis: AxisConfig, master: AxisParameters) -> AxisParameters:
    written = axis.model_fields_set
    changes: dict[str, Any] = {
        "logical_number": axis.logical_number, "clone_of": axis.clone_of, "cloned": True,
    }
    if "link_to" in written and axis.link_to is not None:
        changes["link_to"] = axis.link_to
    if "auto_release_of_axis_link" in written:
        changes["auto_release_of_axis_link"] = axis.auto_release_of_axis_link
    if "limits" in written:
        for name in axis.limits.model_fields_set:
            changes[name] = getattr(axis.limits, name)
    return replace(master, **changes)


def initialise_axes(
    config: MachineConfig,
) -> tuple[dict[int, AxisParameters], list[AxisMessage]]:
    """Effective parameters of every logical axis, and the messages of the clones that
    could not be cloned."""
    done: dict[int, AxisParameters] = {}
    messages: list[AxisMessage] = []
    for channel_index, axis in config.startup_axes():
        master = done.get(axis.clone_of) if axis.clone_of is not None else None
        if axis.clone_of is not None and master is None:
            where = (
                "does not exist" if config.axis(axis.clone_of) is None
                else "is not initialised yet (it comes later in start-up order)"
            )
            messages.append(AxisMessage(
                AxisErrorId.CLONE_MASTER_MISSING,
                f"axis {axis.name} ({axis.logical_number}): master axis {axis.clone_of} of "
                f"kopf.clone_of (P-AXIS-00040) {where}",
                channel_index,
            ))
            messages.append(AxisMessage(
                AxisErrorId.CLONE_NOT_CREATED,
                f"axis {axis.name} ({axis.logical_number}) is created without cloning: "
                "only its own parameter list applies",
                channel_index,
            ))
        if master is not None:
            params = _cloned(axis, master)
        else:
            params = _own(axis, config.link_of(axis.logical_number))
        # an axis's own limits are ordered (AxisLimits checks them); a clone's may not be
        if master is not None and params.sw_limit_min_mm >= params.sw_limit_max_mm:
            messages.append(AxisMessage(
                AxisErrorId.CLONE_LIMITS_INCONSISTENT,
                f"axis {axis.name} ({axis.logical_number}): software limits "
                f"{params.sw_limit_min_mm:g}..{params.sw_limit_max_mm:g} mm after cloning are "
                "not ordered; the master's limits apply",
                channel_index,
            ))
            params = replace(
                params, sw_limit_min_mm=master.sw_limit_min_mm,
                sw_limit_max_mm=master.sw_limit_max_mm,
            )
        done[axis.logical_number] = params
    return done, messages


def update_axis(
    axes: dict[int, AxisParameters], changes: dict[str, Any]
) -> tuple[AxisParameters | None, str]:
    """The parameters of one axis after ``changes`` (the dict of an axis parameter
    list: ``logical_number`` plus what it writes), or (None, why not). Clones of the
    axis keep the copy they took at initialisation."""
    number = changes.get("logical_number")
    current = axes.get(number) if number is not None else None
    if current is None:
        return None, f"there is no axis with kopf.achs_nr {number}"
    if "clone_of" in changes and changes["clone_of"] != current.clone_of:
        return None, (
            f"the clone reference of axis {number} (kopf.clone_of, P-AXIS-00040) cannot "
            "change after the first initialisation"
        )
    if "link_to" in changes and changes["link_to"] != current.link_to:
        return None, (
            f"kopf.link_to of axis {number} is fixed while the service runs; "
            "change the configuration and restart"
        )
    new: dict[str, Any] = {}
    if "auto_release_of_axis_link" in changes:
        new["auto_release_of_axis_link"] = bool(changes["auto_release_of_axis_link"])
    for name, value in (changes.get("limits") or {}).items():
        if name not in _LIMIT_FIELDS:
            return None, f"unknown limit {name!r}"
        new[name] = float(value)
    updated = replace(current, **new)
    if updated.sw_limit_min_mm >= updated.sw_limit_max_mm:
        return None, (
            f"software limits of axis {number} would be {updated.sw_limit_min_mm:g}.."
            f"{updated.sw_limit_max_mm:g} mm: the negative limit must be below the positive"
        )
    for name in ("vel_max_mm_s", "acc_max_mm_s2"):
        if getattr(updated, name) <= 0:
            return None, f"{name} of axis {number} must be positive"
    return updated, ""


UNLIMITED_MM = (-math.inf, math.inf)  # an axis whose software limits are not monitored


def monitored_limits_mm(params: AxisParameters, referenced: bool) -> tuple[float, float]:
    """The software limits in force for an axis (``UNLIMITED_MM`` when not monitored):
    P-AXIS-00705 ``kenngr.swe_check`` -1 (ISG's default) monitors them once the axis is
    referenced, 0 never, 1 always."""
    check = params.sw_limit_check
    if check == 1 or (check == -1 and referenced):
        return params.sw_limit_min_mm, params.sw_limit_max_mm
    return UNLIMITED_MM
