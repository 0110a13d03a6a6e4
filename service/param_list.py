"""Readers for ISG-style parameter lists: axis lists (P-AXIS-*) and channel lists (P-CHAN-*).

An ISG CNC kernel (Beckhoff TwinCAT CNC) is configured with text lists, one ``key value``
a line::

    kopf.achs_nr            11
    kopf.link_to            1      # P-AXIS-00101
    getriebe[0].dynamik.vb_max   250000   # um/s

Keys are dotted names with optional ``[n]`` indices (``n`` a non-negative decimal
integer); one or more spaces or tabs separate key and value; ``#`` starts a comment,
on a line of its own or after the value; blank lines are ignored. ISG writes keys in
lower case; they are matched case-insensitively here, so a list typed with the caps
lock on is still read (``KOPF.ACHS_NR`` is ``kopf.achs_nr``).

The parsers turn a list into a plain dict keyed by this project's configuration field
names (see ``service/config.py``), holding only the parameters the list gives: a
clone's list names only what differs from its master, so absence must stay visible.
Every problem of a list is collected, with file and line, and raised together in one
:class:`ParamListError`, so one run shows everything that needs fixing.

Only the subset of parameters this kernel uses is supported; any other key is a
problem rather than silently ignored, because a parameter the kernel does not honour
would make the machine behave other than its list says.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cnc_objects.protocol.units import UM01_PER_MM

__all__ = [
    "ParamListError",
    "Problem",
    "parse_axis_list",
    "parse_channel_list",
    "read_axis_list",
    "read_channel_list",
]


@dataclass(frozen=True, slots=True)
class Problem:
    """One problem of a parameter list, with its place (line 0: the list as a whole)."""

    file: str
    line: int
    message: str

    def __str__(self) -> str:
        return f"{self.file}:{self.line}: {self.message}"


class ParamListError(ValueError):
    """A parameter list was refused; ``problems`` holds all of its problems, by line."""

    problems: tuple[Problem, ...]

    def __init__(self, problems: Iterable[Problem]) -> None:
        # Stable sort: problems of one line keep the order they were found in.
        self.problems = tuple(sorted(problems, key=lambda p: (p.file, p.line)))
        super().__init__("\n".join(str(p) for p in self.problems))


# --- values -------------------------------------------------------------------------


class _Bad(Exception):
    """A refused value; the message does not name the key (the caller prefixes it)."""


_INTEGER = re.compile(r"[+-]?[0-9]+|(?P<hex>0[xX][0-9a-fA-F]+)")


def _integer(text: str, low: int, high: int) -> int:
    # Hex carries no sign: ISG writes hex for bit masks and type codes, never negatives,
    # and a two's-complement reading of 0xFFFFFFFF for a signed value would be a guess.
    match = _INTEGER.fullmatch(text)
    if match is None:
        raise _Bad(f"{text!r} is not an integer (decimal, or hex 0x...)")
    number = int(text, 16) if match["hex"] else int(text, 10)
    if not low <= number <= high:
        raise _Bad(f"{text} is out of range {low}..{high}")
    return number


def _ranged(low: int, high: int) -> Callable[[str], int]:
    return lambda text: _integer(text, low, high)


_UNS16 = _ranged(1, 0xFFFF)  # 0 is no valid axis number in ISG, hence from 1
_UNS32 = _ranged(1, 0xFFFF_FFFF)
_SGN32 = _ranged(-(2**31), 2**31 - 1)
_swe_check = _ranged(-1, 1)  # SGN08 of P-AXIS-00705: -1 by axis type, 0 off, 1 on


def _boolean(text: str) -> bool:
    if text not in ("0", "1"):
        raise _Bad(f"{text!r} is not a BOOLEAN (0 or 1)")
    return text == "1"


_PROGRAM_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.\-]{0,82}")


def _program_name(text: str) -> str:
    if _PROGRAM_NAME.fullmatch(text) is None:
        raise _Bad(f"{text!r} is not a program name (letters, digits, _ - .)")
    return text


_LINEAR, _ROTARY, _SPINDLE = 1, 2, 4
_AXIS_TYPES = {"ACHSTYP_TRANSLATOR": _LINEAR, "ACHSTYP_ROTATOR": _ROTARY,
               "ACHSTYP_SPINDEL": _SPINDLE}


def _axis_type(text: str) -> int:
    # Kept as the ISG code here; whether the kernel can drive that type is decided once
    # the whole list is known (a spindle's problem depends on kopf.clone_of).
    code = _AXIS_TYPES.get(text.upper())
    if code is None:
        try:
            code = _integer(text, 0, 0xFFFF)
        except _Bad:
            code = None
    if code not in (_LINEAR, _ROTARY, _SPINDLE):
        raise _Bad(f"{text!r} is not an axis type (ACHSTYP_TRANSLATOR 0x0001, "
                   "ACHSTYP_ROTATOR 0x0002, ACHSTYP_SPINDEL 0x0004)")
    return code


# ISG allows a letter A B C Q U V W X Y Z, then letters and digits (its own example
# X_ACHSE1 has an underscore, so that is let through this first check too).
_ISG_AXIS_NAME = re.compile(r"[ABCQUVWXYZ][A-Z0-9_]{0,14}", re.ASCII | re.IGNORECASE)


def _axis_name(text: str) -> str:
    if _ISG_AXIS_NAME.fullmatch(text) is None:
        raise _Bad(f"{text!r} is not an axis name (a letter A B C Q U V W X Y Z, then "
                   "letters or digits, at most 15 characters)")
    if len(text) != 1:
        raise _Bad(f"{text!r} is a valid ISG axis name, but this kernel's NC decoder takes "
                   "single-letter axis names only (A B C Q U V W X Y Z)")
    return text.upper()  # NC programs address axes in capitals


# --- keys and lines -----------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class _Param:
    """A supported parameter: how it is shown, its ISG id, its value, its dict field."""

    shown: str
    pid: str
    convert: Callable[[str], Any]
    field: tuple[str, ...]
    # Set when only index 0 of the key's first index is supported: the message then.
    first_index_zero: str | None = None


@dataclass(frozen=True, slots=True)
class _Item:
    """A supported key as given in a list (first occurrence)."""

    line: int
    key: str  # lower case, indices in plain decimal: getriebe[0].dynamik.vb_max
    indices: tuple[int, ...]
    param: _Param
    value: Any  # converted; _INVALID when the value was refused (and reported)


_INVALID = object()
_SEGMENT = r"[a-z_][a-z0-9_]*(?:\[[0-9]+\])*"
# re.ASCII: under IGNORECASE alone, [a-z] would also match the Kelvin sign and the like.
_KEY = re.compile(rf"{_SEGMENT}(?:\.{_SEGMENT})*", re.ASCII | re.IGNORECASE)
_INDEX = re.compile(r"\[([0-9]+)\]")
_BLANKS = re.compile(r"[ \t]+")


def _scan(text: str, source: str, params: Mapping[str, _Param],
          problems: list[Problem]) -> dict[str, _Item]:
    """Read every line: check key and value, report what is wrong, return the items."""
    supported = ", ".join(p.shown for p in params.values())
    items: dict[str, _Item] = {}
    # Split on "\n" only: str.splitlines would also break at form feeds and other
    # separators and so number lines differently from an editor.
    for number, raw in enumerate(text.split("\n"), start=1):
        body = raw.split("#", 1)[0].strip(" \t\r")
        if not body:
            continue
        key_text, *values = _BLANKS.split(body)

        def report(message: str, line: int = number) -> None:
            problems.append(Problem(source, line, message))

        if _KEY.fullmatch(key_text) is None:
            report(f"malformed key {key_text!r} (expected dotted names with optional [n] "
                   "indices, e.g. gruppe[0].achse[1].bezeichnung)")
            continue
        # Normalise [007] to [7] so that a repeat written differently is still caught.
        key = _INDEX.sub(lambda m: f"[{int(m[1])}]", key_text.lower())
        indices = tuple(int(i) for i in _INDEX.findall(key))
        param = params.get(_INDEX.sub("[]", key))
        if param is None:
            report(f"unknown key {key_text!r} (supported: {supported})")
            continue
        if param.first_index_zero and indices[0] != 0:
            report(f"{key}: {param.first_index_zero}")
            continue
        where = f"{key} ({param.pid})"
        if key in items:
            report(f"{key} given twice, first at line {items[key].line}")
            continue
        value: Any = _INVALID
        if not values:
            report(f"{where}: the value is missing")
        elif len(values) > 1:
            report(f"{where}: one value expected, found {' '.join(values)!r}")
        else:
            try:
                value = param.convert(values[0])
            except _Bad as bad:
                report(f"{where}: {bad}")
        items[key] = _Item(number, key, indices, param, value)
    return items


def _store(result: dict[str, Any], field: tuple[str, ...], value: Any) -> None:
    *outer, last = field
    for name in outer:
        result = result.setdefault(name, {})
    result[last] = value


# --- axis lists ---------------------------------------------------------------------

_GEAR_STAGE_0 = "only getriebe[0] (gear stage 0) is supported"
# Keyed by the key's shape, indices emptied ("getriebe[].dynamik.vb_max"), which is what
# _scan looks up; the index a shape allows is checked by first_index_zero.
_AXIS_PARAMS = {
    param.shown.replace("[0]", "[]"): param
    for param in (
        _Param("kopf.achs_nr", "P-AXIS-00016", _UNS16, ("logical_number",)),
        _Param("kopf.link_to", "P-AXIS-00101", _UNS16, ("link_to",)),
        _Param("kopf.clone_of", "P-AXIS-00040", _UNS16, ("clone_of",)),
        _Param("kenngr.auto_release_of_axis_link", "P-AXIS-00483", _boolean,
               ("auto_release_of_axis_link",)),
        _Param("kenngr.achs_typ", "P-AXIS-00018", _axis_type, ("axis_type",)),
        # 0.1 um in the list, mm in the configuration.
        _Param("kenngr.swe_neg", "P-AXIS-00177", lambda t: _SGN32(t) / UM01_PER_MM,
               ("limits", "sw_limit_min_mm")),
        _Param("kenngr.swe_pos", "P-AXIS-00178", lambda t: _SGN32(t) / UM01_PER_MM,
               ("limits", "sw_limit_max_mm")),
        _Param("kenngr.swe_check", "P-AXIS-00705", _swe_check, ("limits", "sw_limit_check")),
        # um/s in the list, mm/s in the configuration.
        _Param("getriebe[0].dynamik.vb_max", "P-AXIS-00212", lambda t: _UNS32(t) / 1_000,
               ("limits", "vel_max_mm_s"), _GEAR_STAGE_0),
        _Param("getriebe[0].dynamik.a_max", "P-AXIS-00008", lambda t: float(_UNS32(t)),
               ("limits", "acc_max_mm_s2"), _GEAR_STAGE_0),
    )
}


def parse_axis_list(text: str, source: str) -> dict[str, Any]:
    """Parse an axis parameter list; ``source`` names it in problems.

    Returns the parameters present, under configuration field names:
    ``logical_number``, ``link_to``, ``clone_of`` (ints), ``auto_release_of_axis_link``
    (bool), ``axis_type`` (``"linear"``) and ``limits`` (a dict of ``sw_limit_min_mm``,
    ``sw_limit_max_mm``, ``vel_max_mm_s``, ``acc_max_mm_s2``, in mm, mm/s and mm/s^2).
    ``kopf.achs_nr`` is required. Raises :class:`ParamListError` with every problem.
    """
    problems: list[Problem] = []
    items = _scan(text, source, _AXIS_PARAMS, problems)
    if "kopf.achs_nr" not in items:
        problems.append(Problem(source, 0, "kopf.achs_nr is missing (P-AXIS-00016, required)"))
    result: dict[str, Any] = {}
    for item in items.values():
        if item.value is _INVALID:
            continue
        if item.key == "kenngr.achs_typ":
            if item.value == _SPINDLE:
                # A spindle clone is refused by ISG itself; saying so is the more useful
                # message, as dropping clone_of alone would not make the list acceptable.
                message = ("spindle axes cannot be cloned (kopf.clone_of, P-AXIS-00040)"
                           if "kopf.clone_of" in items else
                           "spindle axes (kenngr.achs_typ 4) are not supported by this kernel")
                problems.append(Problem(source, item.line, message))
                continue
            _store(result, item.param.field, "rotary" if item.value == _ROTARY else "linear")
            continue
        _store(result, item.param.field, item.value)
    if problems:
        raise ParamListError(problems)
    return result


# --- channel lists ------------------------------------------------------------------

_ONE_GROUP = "only gruppe[0] is supported (one axis group, as in ISG)"
_CHANNEL_PARAMS = {
    param.shown.replace("[0]", "[]").replace("[n]", "[]"): param
    for param in (
        _Param("gruppe[0].achs_anzahl", "P-CHAN-00003", _ranged(1, 32), ("count",),
               _ONE_GROUP),
        _Param("gruppe[0].achse[n].log_achs_nr", "P-CHAN-00035", _UNS16,
               ("logical_number",), _ONE_GROUP),
        _Param("gruppe[0].achse[n].bezeichnung", "P-CHAN-00006", _axis_name, ("name",),
               _ONE_GROUP),
        _Param("jog_of_path_only", "P-CHAN-00306", _boolean, ("jog_of_path_only",)),
        _Param("syn_chk.errors_total", "P-CHAN-00019", _ranged(0, 0xFFFF),
               ("syn_chk", "errors_total")),
        _Param("syn_chk.fehler_gesamt", "P-CHAN-00019", _ranged(0, 0xFFFF),
               ("syn_chk", "errors_total")),
        _Param("syn_chk.errors_per_block", "P-CHAN-00020", _ranged(0, 0xFFFF),
               ("syn_chk", "errors_per_block")),
        _Param("syn_chk.fehler_pro_zeile", "P-CHAN-00020", _ranged(0, 0xFFFF),
               ("syn_chk", "errors_per_block")),
        _Param("syn_chk.interactive", "P-CHAN-00028", _boolean, ("syn_chk", "interactive")),
        _Param("syn_chk.record_result", "P-CHAN-00416", _boolean,
               ("syn_chk", "record_result")),
        *(param for mode in ("deselect", "rough", "prefinish", "finish") for param in (
            _Param(f"hscs.{mode}.prog", "hscs", _program_name, ("hscs", mode, "prog")),
            _Param(f"hscs.{mode}.tolerance", "hscs", _ranged(0, 0x7FFFFFFF),
                   ("hscs", mode, "tolerance")),
        )),
    )
}
_AXIS_FIELDS = {"name": "bezeichnung", "logical_number": "log_achs_nr"}


def parse_channel_list(text: str, source: str) -> dict[str, Any]:
    """Parse a channel parameter list; ``source`` names it in problems.

    Returns ``{"axes": [{"name": "X", "logical_number": 11}, ...], "jog_of_path_only":
    bool, "syn_chk": {"errors_total": 20, ...}, "hscs": {"finish": {"prog": ..}}}``
    with each key only when the list gives it (``axes`` when any ``gruppe[0]``
    key is there), axes in ``achse`` index order. Names are returned in capitals.
    ``gruppe[0].achs_anzahl`` is required with axes and must equal their number; achse
    indices run 0, 1, 2, ... without gaps; names and numbers are unique. Raises
    :class:`ParamListError` with every problem.
    """
    problems: list[Problem] = []
    items = _scan(text, source, _CHANNEL_PARAMS, problems)
    result: dict[str, Any] = {}
    jog = items.get("jog_of_path_only")
    if jog is not None and jog.value is not _INVALID:
        result["jog_of_path_only"] = jog.value
    for key, item in items.items():  # syn_chk.*: new and old spellings, one field each
        if key.startswith("syn_chk.") and item.value is not _INVALID:
            field = item.param.field
            if field[-1] in result.get("syn_chk", {}):
                problems.append(Problem(source, item.line, f"{key} ({item.param.pid}) sets "
                                        f"syn_chk.{field[-1]} a second time"))
                continue
            _store(result, field, item.value)
        elif key.startswith("hscs.") and item.value is not _INVALID:
            _store(result, item.param.field, item.value)
    if any(key.startswith("gruppe[") for key in items):
        result["axes"] = _channel_axes(items, source, problems)
    if problems:
        raise ParamListError(problems)
    return result


def _channel_axes(items: dict[str, _Item], source: str,
                  problems: list[Problem]) -> list[dict[str, Any]]:
    """Check the gruppe[0] entries as a whole and return the axes in index order."""
    axes: dict[int, dict[str, _Item]] = {}
    for item in items.values():
        if len(item.indices) == 2:  # gruppe[0].achse[k].*
            axes.setdefault(item.indices[1], {})[item.param.field[0]] = item

    def report(line: int, message: str) -> None:
        problems.append(Problem(source, line, message))

    previous = -1
    for k in sorted(axes):
        if k != previous + 1:
            gap = f"{previous + 1}" if k == previous + 2 else f"{previous + 1}..{k - 1}"
            report(min(i.line for i in axes[k].values()),
                   f"gruppe[0].achse[{k}] leaves a gap: no gruppe[0].achse[{gap}] "
                   "(achse indices must run 0, 1, 2, ... without gaps)")
        previous = k
        for field, isg in _AXIS_FIELDS.items():
            if field not in axes[k]:
                (given,) = axes[k].values()
                report(given.line, f"gruppe[0].achse[{k}] has "
                       f"{given.key.rsplit('.', 1)[1]} but no {isg} (both are needed)")

    count = items.get("gruppe[0].achs_anzahl")
    if count is None:
        report(0, "gruppe[0].achs_anzahl is missing (P-CHAN-00003, required with axes)")
    elif count.value is not _INVALID and count.value != len(axes):
        report(count.line, f"gruppe[0].achs_anzahl (P-CHAN-00003) is {count.value} but "
               f"{len(axes)} axes are listed (gruppe[0].achse[...])")

    # In line order, so that a repeat is reported where it is, not where the original is.
    for field, isg in _AXIS_FIELDS.items():
        seen: dict[Any, _Item] = {}
        in_line_order = sorted((a[field] for a in axes.values() if field in a),
                               key=lambda i: i.line)
        for item in in_line_order:
            if item.value is _INVALID:
                continue
            first = seen.setdefault(item.value, item)
            if first is not item:
                report(item.line, f"{item.key}: {item.value} repeats the {isg} of "
                       f"gruppe[0].achse[{first.indices[1]}] (line {first.line}); "
                       "each must be unique")

    return [{field: axes[k][field].value for field in _AXIS_FIELDS if field in axes[k]}
            for k in sorted(axes)]


# --- files --------------------------------------------------------------------------


def _read_text(path: Path) -> str:
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise ParamListError([Problem(str(path), 0, f"cannot read the file: "
                                      f"{exc.strerror or exc}")]) from exc
    try:
        return data.decode("utf-8-sig")  # -sig: lists saved by Windows editors may carry a BOM
    except UnicodeDecodeError:
        pass
    try:
        # Lists written on Windows (umlauts in comments) are often cp1252.
        return data.decode("cp1252")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise ParamListError([Problem(str(path), line, "neither UTF-8 nor cp1252 text (byte "
                                      f"0x{data[exc.start]:02X})")]) from None


def read_axis_list(path: Path) -> dict[str, Any]:
    """Read and parse the axis parameter list at ``path`` (UTF-8, else cp1252).

    A file that cannot be read gives :class:`ParamListError` with a problem at line 0.
    """
    return parse_axis_list(_read_text(path), str(path))


def read_channel_list(path: Path) -> dict[str, Any]:
    """Read and parse the channel parameter list at ``path`` (UTF-8, else cp1252).

    A file that cannot be read gives :class:`ParamListError` with a problem at line 0.
    """
    return parse_channel_list(_read_text(path), str(path))
