"""Every writable object written with extreme values: 0, -1, the type's minimum and
maximum, NaN, +-inf, the smallest subnormal, over-long strings, bytes that are not CP1252,
and data of the wrong size (the wrong type). Each write gets a clear ADS error with a
message, or is taken and reads back as written (or as the object documents: the contour
look-ahead's semaphore is reset by the CNC, a string ends at its first NUL); the kernel
keeps its cycle after every object; the values are put back afterwards.

Writes go out as raw frames (``write_raw``: the bytes as given, no client-side check),
at the object's address, by handle (0xF005) and in a sum write (0xF081).
"""

from __future__ import annotations

import math
import struct
from collections import Counter

import pytest

from cnc_objects.clients import AdsError, Client, ObjectInfo
from cnc_objects.protocol import sum as sums
from cnc_objects.protocol.constants import ReservedIndexGroup as RIG
from cnc_objects.protocol.datatypes import STRING_ENCODING, parse_type
from cnc_objects.protocol.errors import AdsReturnCode as E
from cnc_objects.testing import ServiceProcess, serving
from tests.reliability import figures
from tests.reliability.health import assert_well, vitals, wait_for_tick_after

NODE = "tests/reliability/test_extreme_values.py"
CLIENT_TIMEOUT_S = 20.0
#: The answers a write may get: taken, or refused with a reason the client can act on.
#: (0x701: a function the channel's configuration leaves out, e.g. contour look-ahead.)
ALLOWED = {0, E.DEVICE_SRVNOTSUPP, E.DEVICE_INVALIDSIZE, E.DEVICE_INVALIDDATA,
           E.DEVICE_NOTREADY, E.DEVICE_NOTFOUND, E.DEVICE_BUSY}
#: Objects whose value the CNC changes itself after a write (documented in the catalog).
SELF_RESETTING = {"semaphor_rw"}  # TRUE: the CNC answers and resets it to FALSE
#: Kept in whole kernel cycles (a tool's cutting time counts cycles): a value reads back
#: as the nearest whole number of cycles times the cycle time (-0 and a subnormal as 0).
IN_CYCLES = {"life_used"}
CYCLE_S = 0.001  # the test service's cycle time (the default machine's 1 ms)
_INT_FORMATS = {1: "b", 2: "h", 4: "i", 8: "q"}


def extremes(info: ObjectInfo) -> list[tuple[str, bytes, set[int] | None]]:
    """(label, data, the codes it must get or None for any allowed) for ``info``."""
    dtype = parse_type(info.type)
    size = dtype.size
    wrong_size = {E.DEVICE_INVALIDSIZE}
    cases: list[tuple[str, bytes, set[int] | None]] = [
        ("no bytes", b"", wrong_size if dtype.kind != "str" else None),
        ("one byte too many", bytes(size + 1), wrong_size),
        ("64 kB", b"\x01" * 65536, wrong_size),
    ]
    if size > 1:
        short = None if dtype.kind == "str" else wrong_size  # a string may be shorter
        cases.append(("one byte too few", bytes(size - 1), short))
    match dtype.kind:
        case "bool":
            cases += [("FALSE", b"\x00", None), ("TRUE", b"\x01", None),
                      ("2", b"\x02", {E.DEVICE_INVALIDDATA}),
                      ("255", b"\xff", {E.DEVICE_INVALIDDATA})]
        case "int":
            fmt = "<" + (_INT_FORMATS[size].upper() if dtype.minimum == 0 else _INT_FORMATS[size])
            cases += [(str(v), struct.pack(fmt, v), None)
                      for v in sorted({0, 1, dtype.minimum, dtype.maximum})]
            cases.append(("-1", b"\xff" * size, None))
        case "float":
            cases += [(label, struct.pack("<d", v), None) for label, v in [
                ("0", 0.0), ("-0", -0.0), ("-1", -1.0), ("max", 1.7976931348623157e308),
                ("-max", -1.7976931348623157e308), ("subnormal", 5e-324)]]
            cases += [(label, struct.pack("<d", v), {E.DEVICE_INVALIDDATA})
                      for label, v in [("NaN", math.nan), ("+inf", math.inf), ("-inf", -math.inf)]]
        case "str":
            cases += [
                ("NUL only", b"\x00", None),
                ("a NUL b", b"a\x00b", None),
                ("full", b"x" * (size - 1) + b"\x00", None),
                ("no NUL", b"x" * size, wrong_size),
                ("twice too long", b"x" * (2 * size), wrong_size),
                ("not CP1252", b"\x81\x8d\x8f\x90\x9d\x00", {E.DEVICE_INVALIDDATA}),
                ("control characters", bytes(range(1, 32)) + b"\x00", None),
            ]
    return cases


def readback(info: ObjectInfo, catalog: dict[str, ObjectInfo]) -> ObjectInfo | None:
    """The object a write to ``info`` can be read back from: itself when readable, its
    ``_r`` companion for a ``_w`` object that has one, else None (a command)."""
    if "r" in info.access:
        return info
    if info.name.endswith("_w"):
        return catalog.get(info.name[:-2] + "_r")
    return None


def expected_back(info: ObjectInfo, data: bytes) -> bytes:
    """What a taken write must read back as."""
    if info.name.rsplit(".", 1)[-1] in SELF_RESETTING:
        return b"\x00"
    if info.name.rsplit(".", 1)[-1] in IN_CYCLES:
        (value,) = struct.unpack("<d", data)
        return struct.pack("<d", round(value / CYCLE_S) * CYCLE_S)
    if info.type.startswith("STRING"):
        text = data.split(b"\x00", 1)[0]
        return text.ljust(info.length, b"\x00")
    return data


def sum_write(client: Client, info: ObjectInfo, handle: int, data: bytes) -> int:
    """The item code of a one-item sum write of ``data`` to ``handle``."""
    payload, _ = sums.encode_sum_write([sums.SumItem(RIG.SYM_VALUE_BY_HANDLE, handle, 0, data)])
    reply = client.read_write_raw(info.port, RIG.SUM_WRITE, 1, payload, 4)
    return sums.decode_codes(1, reply)[0]


@pytest.fixture(scope="module")
def service() -> ServiceProcess:
    with serving() as running:
        yield running


def test_every_writable_object_takes_extremes_or_refuses_them_clearly(
    service: ServiceProcess,
) -> None:
    before = vitals(service.endpoint)
    outcomes: Counter[str] = Counter()
    problems: list[str] = []
    with Client(service.endpoint, timeout_s=CLIENT_TIMEOUT_S) as client:
        catalog = {o.name: o for o in client.browse("*")}
        writable = [o for o in catalog.values() if "w" in o.access]
        saved = {o.name: client.read(o.name) for o in writable if "r" in o.access}
        saved_r = {o.name: client.read(r.name) for o in writable
                   if "r" not in o.access and (r := readback(o, catalog)) is not None}
        tick = before.tick
        writes = 0
        for info in writable:
            handle = int.from_bytes(client.read_write_raw(
                info.port, RIG.SYM_HANDLE_BY_NAME, 0,
                info.name.encode(STRING_ENCODING) + b"\x00", 4), "little")
            back_info = readback(info, catalog)
            for label, data, must in extremes(info):
                try:
                    client.write_raw(info.port, info.group, info.offset, data)
                    code = 0
                except AdsError as exc:
                    code = exc.code
                    if not exc.detail:
                        problems.append(f"{info.name} <- {label}: {exc.code:#x} without a message")
                writes += 1
                outcomes[f"{code:#x}"] += 1
                if code not in ALLOWED or (must is not None and code not in must):
                    problems.append(f"{info.name} <- {label}: {code:#x}, expected "
                                    f"{sorted(hex(c) for c in (must or ALLOWED))}")
                elif code == 0 and back_info is not None:
                    got = client.read_raw(back_info.port, back_info.group, back_info.offset,
                                          back_info.length)
                    if got != expected_back(info, data):
                        problems.append(f"{info.name} <- {label}: taken, but {back_info.name} "
                                        f"reads {got[:16]!r}")
                if must == {E.DEVICE_INVALIDSIZE}:  # the same bytes by handle and in a sum
                    for path, code_of in (
                        ("by handle", lambda: _by_handle(client, info, handle, data)),
                        ("in a sum write", lambda: sum_write(client, info, handle, data)),
                    ):
                        writes += 1
                        got_code = code_of()
                        outcomes[f"{got_code:#x}"] += 1
                        if got_code != E.DEVICE_INVALIDSIZE:
                            problems.append(f"{info.name} <- {label} {path}: {got_code:#x}")
            tick = wait_for_tick_after(service.endpoint, tick)  # the cycle goes on
        # put everything back: channels reset, the values as they were
        for channel in (1, 2):
            client.reset_to_standard(channel)
        for name, value in saved.items():
            if name.rsplit(".", 1)[-1] not in SELF_RESETTING:
                client.write(name, value)
        for name, value in saved_r.items():
            client.write(name, value)
        assert {n: client.read(n) for n in saved} == saved
    assert_well(service, tick, before)
    summary = ", ".join(f"{code} x{n}" for code, n in sorted(outcomes.items()))
    print(f"\nextreme values: {writes} raw writes to {len(writable)} writable objects: {summary}")
    figures.record("extreme-value writes to every writable object",
                   f"{writes} writes to {len(writable)} objects: {summary}", NODE)
    assert not problems, "\n".join(problems)


def _by_handle(client: Client, info: ObjectInfo, handle: int, data: bytes) -> int:
    """The code of a write of ``data`` by handle (0xF005)."""
    try:
        client.write_raw(info.port, RIG.SYM_VALUE_BY_HANDLE, handle, data)
    except AdsError as exc:
        return exc.code
    return 0
