"""The machine as the kernel sees it: axes, channels, tools, look-ahead, cycle time.

Pydantic models, validated once at start (``config.load_config``); the kernel imports
this module and nothing else of the service (tests/test_import_graph.py), so it cannot
depend on front ends, keys or limits. The embedded default machine is ``DEFAULT_MACHINE``.
"""

from __future__ import annotations

import copy
from enum import IntEnum, StrEnum
from typing import TYPE_CHECKING, Any, Literal

from pydantic import AliasChoices, BaseModel, ConfigDict, Field, field_validator, model_validator

if TYPE_CHECKING:
    from .kernel.path.kinematics import Kinematics


class Strict(BaseModel):
    """A configuration table: unknown keys refused, values frozen."""

    model_config = ConfigDict(extra="forbid", frozen=True)


class AxisLimits(Strict):
    """Limits the planner and the position controller respect for one axis."""

    vel_max_mm_s: float = Field(500.0, gt=0, description="maximum axis velocity (mm/s)")
    acc_max_mm_s2: float = Field(5000.0, gt=0, description="maximum acceleration (mm/s^2)")
    sw_limit_min_mm: float = Field(-1000.0, description="negative software limit (mm)")
    sw_limit_max_mm: float = Field(1000.0, description="positive software limit (mm)")
    vel_jump_mm_s: float = Field(
        20.0, ge=0, description="permitted velocity jump of the axis at a block junction (mm/s)"
    )
    sw_limit_check: Literal[-1, 0, 1] = Field(
        -1, description="P-AXIS-00705 kenngr.swe_check: -1 the software limits are "
        "monitored once the axis is referenced (ISG's default for a translatory axis), "
        "0 never, 1 always (also before homing)")

    @model_validator(mode="after")
    def _limits_ordered(self) -> AxisLimits:
        if self.sw_limit_min_mm >= self.sw_limit_max_mm:
            raise ValueError("sw_limit_min_mm must be below sw_limit_max_mm")
        return self


class ManualAxisConfig(Strict):
    """Manual mode and homing of one axis (docs/manual.md): jog speeds, handwheel
    resolution, homing speed and end position."""

    jog_vel_mm_s: float = Field(
        16.666, gt=0, description="continuous and incremental jog speed (mm/s), as ISG's "
        "P-AXIS-00077 handbetrieb.tipp.geschw[0] (default 16666 um/s); shown as "
        "hb_display_r.tipp_geschw; capped at vel_max_mm_s")
    jog_rapid_vel_mm_s: float = Field(
        100.0, gt=0, description="jog speed while the rapid key is pressed (rapid "
        "override, mm/s), as ISG's P-AXIS-00530 handbetrieb.jog.rapid_velocity; capped "
        "at vel_max_mm_s")
    handwheel_resolution_incr: int = Field(
        10, ge=1, le=100_000, description="path per handwheel pulse (0.1 um), "
        "hb_display_r.hr_aufloesung; the HMI/PLC may change it")
    homing_vel_mm_s: float = Field(
        10.0, gt=0, description="speed of the homing run (G74 or homing_start_w, mm/s)")
    prog_move_requires_homing: bool | None = Field(
        None, description="P-AXIS-00277 kenngr.prog_move_requires_homing: a program block "
        "that moves this axis before it is referenced is an error (error 50110, issue 39); "
        "left out: the machine's programs_need_referenced_axes (default false, ISG's 0)")
    pos_refpkt_mm: float = Field(
        0.0, description="P-AXIS-00152 kenngr.pos_refpkt: the position the axis "
        "takes at the end of homing (mm)")


class PhysicalAxisConfig(Strict):
    """A drive of the platform."""

    number: int = Field(ge=1, le=0xFFFF, description="physical axis number (link target)")
    name: str = Field(min_length=1, max_length=15)




class AxisConfig(Strict):
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
    axis_type: Literal["linear", "rotary"] = Field(
        "linear", description="kenngr.achs_typ (P-AXIS-00018): a rotary axis is "
        "programmed, limited and shown in degrees (its limits' _mm values are degrees), "
        "and tracks the main axes (docs/kernel.md \"Rotary axes\")")
    auto_release_of_axis_link: bool = Field(
        False, description="kenngr.auto_release_of_axis_link (P-AXIS-00483)"
    )
    limits: AxisLimits = AxisLimits()
    manual: ManualAxisConfig = ManualAxisConfig()


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


class ToolConfig(Strict):
    """One entry of the tool list wz[d]: D (and T) number, radius and length."""

    d: int = Field(ge=1, le=9999, description="tool offset number (D word; T names it too)")
    radius_mm: float = Field(ge=0, description="tool radius (mm)")
    length_mm: float = Field(0.0, ge=-214748.3647, le=214748.3647,
                             description="tool length along the tool axis (mm)")


class SyntaxCheckConfig(Strict):
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


class HscsModeConfig(Strict):
    """One mode of the high-speed settings (SysHscSettings): ``hscs.<mode>.*``."""

    prog: str = Field("", max_length=83, description="program the cycle calls (L <prog>)")
    tolerance: int = Field(
        0, ge=0, le=0x7FFFFFFF,
        description="machining tolerance in 0.1 um; NC programs read it in mm as "
        "V.G.HSCS.<MODE>.TOLERANCE",
    )


def _hscs_default(mode: str, tolerance: int) -> HscsModeConfig:
    return HscsModeConfig(prog=f"manufacturerHsc{mode}Settings.nc", tolerance=tolerance)


class HscsConfig(Strict):
    """Channel parameters of the SysHscSettings cycle (``hscs.<mode>.prog/.tolerance``).
    The defaults name the example programs of the cycle documentation (docs/examples/hsc)."""

    deselect: HscsModeConfig = Field(default_factory=lambda: _hscs_default("Deselect", 0))
    rough: HscsModeConfig = Field(default_factory=lambda: _hscs_default("Rough", 1000))
    prefinish: HscsModeConfig = Field(default_factory=lambda: _hscs_default("Prefinish", 500))
    finish: HscsModeConfig = Field(default_factory=lambda: _hscs_default("Finish", 100))


class EnhancedLookAheadConfig(Strict):
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


class ProgStartConfig(Strict):
    """ISG's start-up defaults of a channel (channel list ``prog_start.*``)."""

    feedrate: float = Field(
        0.0, ge=0, le=1e7,
        description="P-CHAN-00099 prog_start.feedrate: the feed (mm/min) of a G01/G02/G03 "
        "block when no F was programmed; 0: none (the block is an error)",
    )


class SyncKind(IntEnum):
    """ISG's synchronisation kinds of M/H/S/T functions (``m_synch[i]`` values)."""

    NO_SYNCH = 0x0  # not output to the PLC
    MOS = 0x1  # output, no synchronisation
    MVS_SVS = 0x2  # output before the motion, motion starts after the acknowledge
    MVS_SNS = 0x4  # output before the motion, waited for at the block end
    MNS_SNS = 0x8  # output after the motion, waited for at the block end


NOT_VALID = "NOT_VALID"  # P-CHAN-00041's default: the M function is not defined

# the M functions the embedded default machine defines (P-CHAN-00041 m_synch[i]): those
# its README, tests and example programs use, each MVS_SVS as every unlisted M was before
# issue 39 (spindle M3/M4/M5/M19 take their own keys, M0/M1/M2/M17/M29/M30 are internal)
DEFAULT_M_SYNCH: dict[str, str] = {
    str(m): "MVS_SVS" for m in (6, 7, 8, 9, 10, 11, 12, 13, 25, 40, 80)}


def _sync_kind(value: str) -> str:
    if value not in SyncKind.__members__:
        raise ValueError(f"{value!r} is not a synchronisation kind; use one of "
                         + ", ".join(SyncKind.__members__))
    return value


class SpindleConfig(Strict):
    """The channel's spindle (channel list ``spindel[0].*``, axis list of its S axis)."""

    bezeichnung: str = Field("S", min_length=1, max_length=15,
                             description="P-CHAN-00007 spindel[0].bezeichnung: its name")
    a_max: float = Field(36000.0, gt=0, le=1e9,
                         description="P-AXIS-00008 getriebe[0].dynamik.a_max: acceleration "
                         "(degrees/s^2; 6 degrees/s^2 = 1 rpm/s)")
    max_rpm: float = Field(24000.0, gt=0, le=1e6,
                           description="P-AXIS-00212 vb_max as rpm: the largest speed")
    s_synch: str = Field("MOS", description="P-CHAN-00081 spindel[0].s_synch")
    m3_synch: str = Field("MVS_SVS", description="P-CHAN-00045 spindel[0].m3_synch")
    m4_synch: str = Field("MVS_SVS", description="P-CHAN-00047 spindel[0].m4_synch")
    m5_synch: str = Field("MVS_SVS", description="P-CHAN-00049 spindel[0].m5_synch")
    m19_synch: str = Field("MNS_SNS", description="P-CHAN-00043 spindel[0].m19_synch")
    no_stop_by_channel_reset: bool = Field(
        False, description="P-AXIS-00455 kenngr.no_stop_by_channel_reset: the spindle keeps "
        "turning at a channel RESET (and in ERROR); by default it brakes to a stop")

    @field_validator("s_synch", "m3_synch", "m4_synch", "m5_synch", "m19_synch")
    @classmethod
    def _kind(cls, value: str) -> str:
        return _sync_kind(value)


class PlcFunctionsConfig(Strict):
    """M, H, S and T functions to the PLC: kinds per function, the embedded PLC's acknowledge.

    Keys of ``m_synch`` / ``m_prozess_zeit`` are M numbers ("8" for M8), those of
    ``h_synch`` / ``h_prozess_zeit`` H numbers."""

    m_synch: dict[str, str] = Field(
        default_factory=lambda: dict(DEFAULT_M_SYNCH),
        description="P-CHAN-00041 m_synch[i]: kind of M<i>; the default lists M6 M7 M8 "
        "M9 M10 M11 M12 M13 M25 M40 M80 as MVS_SVS")
    m_synch_default: str = Field(
        NOT_VALID, description="kind of an M function m_synch does not list: NOT_VALID "
        "(ISG's default: the M is an error, 20160), or a kind that such an M takes")
    h_synch: dict[str, str] = Field(
        default_factory=dict, description="P-CHAN-00027 h_synch[i]: kind of H<i>")
    h_synch_default: str = Field(
        "MVS_SVS", description="kind of an H function h_synch does not list (ISG: NOT_VALID)")
    t_synch: str = Field("MOS", description="kind of the T word (project)")
    m_prozess_zeit: dict[str, int] = Field(
        default_factory=dict, description="P-CHAN-00040 m_prozess_zeit[i]: time of M<i> (us)")
    h_prozess_zeit: dict[str, int] = Field(
        default_factory=dict, description="P-CHAN-00026 h_prozess_zeit[i]: time of H<i> (us)")
    prozess_zeit_default: int = Field(
        0, ge=0, le=3_600_000_000, description="time (us) of a function m_prozess_zeit "
        "does not list; the embedded PLC acknowledges after it")
    auto_acknowledge: bool = Field(
        True, description="the embedded PLC acknowledges after the function's time "
        "(kernelv's default); false: the PLC acknowledges over ADS")
    spindel: SpindleConfig = Field(default_factory=SpindleConfig)

    @field_validator("m_synch", "h_synch")
    @classmethod
    def _function_kinds(cls, value: dict[str, str]) -> dict[str, str]:
        for key, kind in value.items():
            if not key.isdigit():
                raise ValueError(f"key {key!r} is not a function number")
            _sync_kind(kind)
        return value

    @field_validator("m_prozess_zeit", "h_prozess_zeit")
    @classmethod
    def _function_times(cls, value: dict[str, int]) -> dict[str, int]:
        for key, time_us in value.items():
            if not key.isdigit():
                raise ValueError(f"key {key!r} is not a function number")
            if not 0 <= time_us <= 3_600_000_000:
                raise ValueError(f"time {time_us} us of function {key} is not in 0..3600000000")
        return value

    @field_validator("h_synch_default", "t_synch")
    @classmethod
    def _kind(cls, value: str) -> str:
        return _sync_kind(value)

    @field_validator("m_synch_default")
    @classmethod
    def _m_default(cls, value: str) -> str:
        return value if value == NOT_VALID else _sync_kind(value)

    def m_known(self, number: int) -> bool:
        """M<number> has a kind: listed, a spindle function, or a default kind set."""
        return (self.m_synch_default != NOT_VALID or str(number) in self.m_synch
                or number in (3, 4, 5, 19))

    def kind(self, type_: int, number: int) -> SyncKind:
        """The kind of function ``number`` of type ``type_`` (1 M, 2 H, 3 S, 4 T)."""
        spindle = self.spindel
        if type_ == 2:
            return SyncKind[self.h_synch.get(str(number), self.h_synch_default)]
        if type_ == 3:
            return SyncKind[spindle.s_synch]
        if type_ == 4:
            return SyncKind[self.t_synch]
        named = {3: spindle.m3_synch, 4: spindle.m4_synch, 5: spindle.m5_synch,
                 19: spindle.m19_synch}.get(number)
        if named is not None:
            return SyncKind[named]
        kind = self.m_synch.get(str(number), self.m_synch_default)
        # NOT_VALID: the decoder refuses such an M (20160); none reaches the PLC
        return SyncKind.NO_SYNCH if kind == NOT_VALID else SyncKind[kind]

    def prozess_zeit_s(self, type_: int, number: int) -> float:
        """The function's time in s (the embedded PLC acknowledges after it)."""
        times = {1: self.m_prozess_zeit, 2: self.h_prozess_zeit}.get(type_, {})
        us = times.get(str(number))
        return (self.prozess_zeit_default if us is None else us) / 1e6


class PlcConfig(Strict):
    """``[plc]``: the short form for a real PLC, laid over every channel's ``techno``
    (docs/configuration.md "A real PLC in three lines")."""

    acknowledges: tuple[str, ...] = Field(
        (), description="functions the PLC acknowledges over ADS, e.g. [\"M6\", \"M8\", "
        "\"M9\"]; the embedded PLC acknowledges the others (auto_acknowledge)")

    @field_validator("acknowledges")
    @classmethod
    def _functions(cls, value: tuple[str, ...]) -> tuple[str, ...]:
        for name in value:
            if len(name) < 2 or name[0].upper() not in "MH" or not name[1:].isdigit():
                raise ValueError(f"{name!r} is not an M or H function (write e.g. \"M8\")")
        return tuple(f"{n[0].upper()}{int(n[1:])}" for n in value)

    def numbers(self, letter: str) -> frozenset[int]:
        """The numbers of the acknowledged functions of ``letter`` ("M" or "H")."""
        return frozenset(int(n[1:]) for n in self.acknowledges if n[0] == letter)


class KinematicAxisConfig(Strict):
    """One axis of a kinematic chain (ISG's Universal Kinematics, P-CHAN-00290 ..
    P-CHAN-00293), in its order from the workpiece to the tool tip."""

    axis: str = Field(min_length=1, max_length=15, description="the channel axis's name")
    type: Literal["translator", "rotator"] = Field(
        description="P-CHAN-00291 trafo[j].axis[k].type: 1 translator, 2 rotator")
    direction: tuple[float, float, float] = Field(
        description="P-CHAN-00292 trafo[j].axis[k].orientation: the axis's direction; "
        "times -1 for an axis on the workpiece side (it moves the workpiece)")
    point_mm: tuple[float, float, float] = Field(
        (0.0, 0.0, 0.0), description="P-CHAN-00293 trafo[j].axis[k].point: a point on a "
        "rotator's line, with every axis at 0 (mm)")


class KinematicsConfig(Strict):
    """A channel's five-axis kinematics (docs/kernel.md "Rotary axes, the feed group and
    the kinematic chain"): three translators and two rotators of the channel."""

    id: int = Field(91, ge=1, le=0xFFFF, description="P-CHAN-00262 trafo[j].id")
    zero_orientation: tuple[float, float, float] = Field(
        (0.0, 0.0, 1.0), description="P-CHAN-00285: the tool's direction (tip towards "
        "spindle) with every axis at 0")
    zero_position_mm: tuple[float, float, float] = Field(
        description="P-CHAN-00286: the tool tip (tool length 0: the spindle nose) with "
        "every axis at 0 (mm)")
    axes: tuple[KinematicAxisConfig, ...] = Field(
        min_length=5, max_length=5, description="P-CHAN-00290: the chain from the "
        "workpiece to the tool tip")


class ChannelConfig(Strict):
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
    g00_override_mode: Literal["NOT_USED", "MINIMUM_OF_G0_G1", "ACTIVE", "ACTIVE_EXTENDED"] = \
        Field("ACTIVE", description="P-CHAN-00181 g00_override_mode: how the rapid override "
              "acts on G0 (ISG's default is NOT_USED; this project's is ACTIVE: the feed "
              "override no longer slows G0)")
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
    prog_start: ProgStartConfig = Field(
        default_factory=ProgStartConfig, description="start-up defaults (prog_start.*)"
    )
    techno: PlcFunctionsConfig = Field(
        default_factory=PlcFunctionsConfig,
        description="M/S/T functions to the PLC and the spindle (docs/spindle-plc.md)",
    )
    kinematics: KinematicsConfig | None = Field(
        None, description="the five-axis kinematics #TRAFO ON selects (none: a "
        "three-axis channel, #TRAFO ON is NC error 20519)")

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

    @model_validator(mode="after")
    def _kinematics_of_this_channel(self) -> ChannelConfig:
        if self.kinematics is not None:
            self.kinematic_chain()  # ValueError (KinematicsError) with the reason
        return self

    def kinematic_chain(self) -> Kinematics | None:
        """The channel's kinematics as the kernel computes with it (None: none)."""
        if self.kinematics is None:
            return None
        # here, not at the top: the kernel's path package imports this module
        from .kernel.path.kinematics import ChainAxis, JointKind, Kinematics

        index = {a.name: k for k, a in enumerate(self.axes)}
        chain = []
        for link in self.kinematics.axes:
            if link.axis not in index:
                raise ValueError(f"kinematics of channel {self.id}: no axis {link.axis!r} "
                                 f"in the channel (its axes: {', '.join(index)})")
            axis = self.axes[index[link.axis]]
            wanted = "linear" if link.type == "translator" else "rotary"
            if axis.axis_type != wanted:
                raise ValueError(f"kinematics of channel {self.id}: {link.axis} is a "
                                 f"{link.type} in the chain but a {axis.axis_type} axis")
            if link.type == "translator" and link.axis not in "XYZ":
                raise ValueError(f"kinematics of channel {self.id}: the translators are the "
                                 f"main axes X, Y, Z (they hold the tool tip), not "
                                 f"{link.axis}")
            chain.append(ChainAxis(index[link.axis], JointKind[link.type.upper()],
                                   link.direction, link.point_mm))
        ranges = [(index[link.axis], self.axes[index[link.axis]].limits.sw_limit_min_mm,
                   self.axes[index[link.axis]].limits.sw_limit_max_mm)
                  for link in self.kinematics.axes if link.type == "rotator"]
        return Kinematics.from_chain(self.kinematics.id, self.kinematics.zero_orientation,
                                     self.kinematics.zero_position_mm, chain, ranges)


class MachineConfig(Strict):
    """The machine the kernel runs: platform axes, channels, tools, cycle time."""

    name: str = Field("cnc-objects", min_length=1, max_length=31)
    cycle_ms: float = Field(1.0, gt=0.05, le=100.0, description="GEO cycle time (ms)")
    physical_axes: tuple[PhysicalAxisConfig, ...] = Field(min_length=1)
    channels: tuple[ChannelConfig, ...] = Field(min_length=1, max_length=12)
    tools: tuple[ToolConfig, ...] = Field((), description="tool table (D number -> radius)")
    programs_need_referenced_axes: bool = Field(
        False, description="the default of every axis' prog_move_requires_homing "
        "(P-AXIS-00277): a program block that moves an unreferenced axis is an error "
        "(docs/manual.md, issue 39); manual blocks (G74 in MDI) still run")
    tool_entries: int = Field(32, ge=1, le=9999,
                              description="rows wz[1..n] of each channel's tool list")
    tool_change_time_s: float = Field(0.0, ge=0.0, le=600.0,
                                      description="M6: time the path waits for the change (s)")
    plc: PlcConfig = Field(default_factory=PlcConfig, description="[plc]: what a real PLC "
                           "acknowledges, for every channel (docs/configuration.md)")
    zero_offset_groups: int = Field(10, ge=7, le=97, description="np_grp[0..n-1] per channel "
                                    "(P-ZERO-00003): G53, G54..G59, G159 = 7..n-1")

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
            # FCT-C15's example moves this channel with `G91 Y10` and no F (section 2.4)
            "prog_start": {"feedrate": 1000.0},
            "axes": [
                {"name": "X", "logical_number": 11, "link_to": 1, "clone_of": 1},
                {"name": "Y", "logical_number": 12, "link_to": 2, "clone_of": 2},
                {"name": "Z", "logical_number": 13, "link_to": 3, "clone_of": 3},
            ],
        },
    ],
}


def _five_axis(name: str, rotary: tuple[dict[str, Any], dict[str, Any]],
               kinematics: dict[str, Any]) -> dict[str, Any]:
    """The default machine with two rotary axes added to channel 1 (drives 4 and 5)
    and its kinematics; channel 2 stays as it is."""
    machine = copy.deepcopy(DEFAULT_MACHINE)
    machine["name"] = name
    for number, axis in enumerate(rotary, start=4):
        machine["physical_axes"].append({"number": number, "name": axis["name"]})
        machine["channels"][0]["axes"].append(
            {"logical_number": number, "link_to": number, "axis_type": "rotary", **axis})
    machine["channels"][0]["kinematics"] = kinematics
    return machine


_TRANSLATORS = [
    {"axis": "X", "type": "translator", "direction": (1.0, 0.0, 0.0)},
    {"axis": "Y", "type": "translator", "direction": (0.0, 1.0, 0.0)},
    {"axis": "Z", "type": "translator", "direction": (0.0, 0.0, 1.0)},
]
# 180 degrees/s (30 rpm), 1800 degrees/s^2: a machine tool's rotary table / head of this size
_ROTARY_DYNAMICS = {"vel_max_mm_s": 180.0, "acc_max_mm_s2": 1800.0, "vel_jump_mm_s": 5.0}

FIVE_AXIS_AC: dict[str, Any] = _five_axis(
    "cnc-objects-5ax-ac",
    ({"name": "A", "limits": {**_ROTARY_DYNAMICS, "sw_limit_min_mm": -120.0,
                              "sw_limit_max_mm": 120.0}},
     {"name": "C", "limits": {**_ROTARY_DYNAMICS, "sw_limit_min_mm": -36000.0,
                              "sw_limit_max_mm": 36000.0}}),
    # a table-table machine: the C table rides on an A cradle whose axis lies 100 mm
    # below the table's face; X Y Z carry the spindle, whose nose (tool length 0) is at
    # the table's centre with every axis at 0, as a three-axis channel's positions have
    # it. Table axes move the workpiece: directions -1.
    {"id": 91, "zero_orientation": (0.0, 0.0, 1.0), "zero_position_mm": (0.0, 0.0, 0.0),
     "axes": [{"axis": "C", "type": "rotator", "direction": (0.0, 0.0, -1.0)},
              {"axis": "A", "type": "rotator", "direction": (-1.0, 0.0, 0.0),
               "point_mm": (0.0, 0.0, -100.0)},
              *_TRANSLATORS]},
)
"""A five-axis machine with a table-table A/C kinematics (``--machine five-axis-ac``)."""

FIVE_AXIS_BC: dict[str, Any] = _five_axis(
    "cnc-objects-5ax-bc",
    ({"name": "B", "limits": {**_ROTARY_DYNAMICS, "sw_limit_min_mm": -95.0,
                              "sw_limit_max_mm": 95.0}},
     {"name": "C", "limits": {**_ROTARY_DYNAMICS, "sw_limit_min_mm": -36000.0,
                              "sw_limit_max_mm": 36000.0}}),
    # a head-table machine: a C table, X Y Z carry a head that swivels about Y (B) at a
    # pivot 150 mm above the spindle nose; the nose is at the table's centre with every
    # axis at 0. The table moves the workpiece: direction -1.
    {"id": 91, "zero_orientation": (0.0, 0.0, 1.0), "zero_position_mm": (0.0, 0.0, 0.0),
     "axes": [{"axis": "C", "type": "rotator", "direction": (0.0, 0.0, -1.0)},
              *_TRANSLATORS,
              {"axis": "B", "type": "rotator", "direction": (0.0, 1.0, 0.0),
               "point_mm": (0.0, 0.0, 150.0)}]},
)
"""A five-axis machine with a head-table B/C kinematics (``--machine five-axis-bc``)."""



class EmbeddedMachine(StrEnum):
    """The machines ``cnc-service --machine NAME`` starts on."""

    THREE_AXIS = "three-axis"  # the default
    FIVE_AXIS_AC = "five-axis-ac"
    FIVE_AXIS_BC = "five-axis-bc"


EMBEDDED_MACHINES: dict[EmbeddedMachine, dict[str, Any]] = {
    EmbeddedMachine.THREE_AXIS: DEFAULT_MACHINE,
    EmbeddedMachine.FIVE_AXIS_AC: FIVE_AXIS_AC,
    EmbeddedMachine.FIVE_AXIS_BC: FIVE_AXIS_BC,
}
"""Each embedded machine's configuration (``--config`` is laid over it)."""
