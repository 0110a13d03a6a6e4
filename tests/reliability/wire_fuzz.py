"""Malformed ZeroMQ frames (hypothesis strategies) and what the service must answer.

A frame here is a ZeroMQ message as a list of parts: the last part is the msgpack frame
(protocol/frames.py), parts before it are extra envelope parts, which a ROUTER hands back
in front of the reply. The strategies make the kinds of bad input a network can bring:

- random bytes, and valid frames cut short (truncated msgpack);
- msgpack of the wrong shape: no array, too few or too many fields, fields of the wrong
  type (floats, strings, maps, nil, booleans, extension types, invalid UTF-8);
- negative and out-of-range integers for invoke ids, commands, ports, groups, offsets
  and lengths (-2**63 .. 2**64-1), huge read lengths;
- msgpack headers that claim huge lengths (arrays, maps, bin, str of 4 GiB), deep nesting;
- frames of the right shape with hostile content: sum commands with garbage item lists,
  names that are no names, notifications in client modes, the program store's offsets;
- extra frame parts before the frame;
- on raw TCP, half-sent frames and connection floods on both front ends
  (``half_sent_floods``): what the service must do with them is ``HalfSent.must_close``
  and the limits' bounds (test_wire_fuzz.py).

``expected_reply`` is the rule the service must follow, stated once: a frame whose
msgpack is an array whose first element is an invoke id (1 .. 2**32-1) gets exactly one
reply with that id, echoed behind the same extra parts; any other frame gets none. The
reply's command and code are those ``protocol.frames.decode_request`` gives (the
sans-I/O decoder the service uses): a frame it refuses is answered with its code.
"""

from __future__ import annotations

import struct
from collections import Counter
from dataclasses import dataclass

import msgpack
from hypothesis import strategies as st

from cnc_objects.objects.addressing import LOGICAL_BIT
from cnc_objects.protocol import sum as sums
from cnc_objects.protocol.constants import (
    PROGRAM_STORE_GROUP,
    AdsCommand,
    AdsState,
    CncPort,
)
from cnc_objects.protocol.constants import ReservedIndexGroup as RIG
from cnc_objects.protocol.errors import AdsReturnCode, ProtocolError
from cnc_objects.protocol.frames import (
    REQUEST_TYPES,
    ReadWriteRequest,
    WriteControlRequest,
    WriteRequest,
    decode_request,
)
from tests.reliability.floods import ads_half_frame, zmtp_greeting, zmtp_half_frame

U32_MAX = 0xFFFFFFFF

EDGE_INTS = [
    0, 1, 2, -1, -2, 127, 128, 255, 256, 0x7FFF, 0x8000, 0xFFFF, 0x10000, 0x7FFFFFFF,
    0x80000000, U32_MAX, U32_MAX + 1, 2**63 - 1, 2**63, 2**64 - 1, -(2**31), -(2**31) - 1,
    -(2**63),
]
#: Index groups that exist (objects, the program store, the reserved ADS groups).
REAL_GROUPS = [
    0x120100, 0x120101, 0x120102, 0x020101, 0x121301, 0x120200, 0x120300, 0x130100,
    0x4020, PROGRAM_STORE_GROUP, *(int(g) for g in RIG),
]
#: (port, group, offset, length) of read-only objects: reads and subscriptions that work.
READABLE = [
    (553, 0x120100, 0x1011, 4),  # cnc_tick_counter_r (changes every cycle)
    (553, 0x120101, 0xA, 2),  # ch1.mc_command_feed_override_r
    (553, 0x120101, 0x3002, 4),  # ch1.mc_active_state_r
    (551, 0x121301, 0x10002, 4),  # ch1.ax1.command_position_acs
    (553, 0x120102, 0x3005, 84),  # ch2.mc_active_program_name_r
]
PORTS = [0, 1, 550, *(int(p) for p in CncPort), 10000, 48898, 0xFFFF, 0x10000, -1]

ints = st.one_of(st.sampled_from(EDGE_INTS), st.integers(-(2**63), 2**64 - 1),
                 st.integers(0, 2000))
u32 = st.one_of(st.sampled_from([0, 1, 2, 4, 0xFFFF, 0x10000, U32_MAX]),
                st.integers(0, U32_MAX), st.integers(0, 64))
invoke_ids = st.one_of(st.integers(1, U32_MAX), st.integers(1, 50))
commands = st.one_of(st.sampled_from([int(c) for c in AdsCommand] + [10, 0xFF, 0x101]), ints)
ports = st.one_of(st.sampled_from(PORTS), ints)
groups = st.one_of(st.sampled_from(REAL_GROUPS), u32)
binaries = st.one_of(st.binary(max_size=64), st.binary(min_size=200, max_size=5000))
scalars = st.one_of(
    st.none(), st.booleans(), ints, st.floats(), st.text(max_size=20), st.binary(max_size=40),
    st.builds(msgpack.ExtType, st.integers(0, 127), st.binary(max_size=8)),
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(st.lists(inner, max_size=6),
                            st.dictionaries(st.text(max_size=5), inner, max_size=4)),
    max_leaves=12,
)


def pack(obj: object) -> bytes:
    """msgpack as clients send it (bin type for bytes)."""
    return msgpack.packb(obj, use_bin_type=True)


@st.composite
def sum_payloads(draw: st.DrawFn) -> bytes:
    """Item lists of sum commands: right-looking headers with garbage, or plain garbage."""
    items = draw(st.lists(st.tuples(groups, u32, u32, u32), max_size=6))
    head = b"".join(struct.pack("<IIII", *item) for item in items)
    cut = draw(st.integers(0, len(head)))
    return head[:cut] + draw(st.binary(max_size=40))


def _field_value(kind: str) -> st.SearchStrategy:
    """A value for a field of ``kind``: mostly of the right type but hostile, sometimes
    of a wrong type."""
    right = {
        "u32": st.one_of(u32, u32, ints),
        "bytes": st.one_of(binaries, sum_payloads()),
        "str": st.one_of(st.text(max_size=30),
                         st.sampled_from(["", "*", "ch1.*", "?", "[", "[!", "gpCh[0].*",
                                          "*" * 40 + "q", "*a" * 30, "[" * 50, "?" * 300])),
    }[kind]
    return st.one_of(right, right, values)


@st.composite
def near_valid(draw: st.DrawFn) -> list:
    """[invoke_id, command, port, *fields]: a real command with hostile or mistyped fields,
    sometimes one field too few or too many."""
    command = draw(st.sampled_from(sorted(REQUEST_TYPES)))
    fields = [draw(_field_value(kind)) for _, kind in REQUEST_TYPES[command].FIELDS]
    if fields and draw(st.integers(0, 3)) == 0:
        # the address fields of a real-looking request
        fields[0] = draw(groups) if REQUEST_TYPES[command].FIELDS[0][1] == "u32" else fields[0]
    match draw(st.integers(0, 7)):
        case 0:
            fields = fields[:-1]
        case 1:
            fields.append(draw(values))
        case _:
            pass
    first = draw(st.one_of(invoke_ids, invoke_ids, values))
    return [first, command if draw(st.integers(0, 5)) else draw(commands), draw(ports), *fields]


@st.composite
def hostile_valid(draw: st.DrawFn) -> list:
    """A request of the right shape and types whose content is hostile: addresses that
    exist and ones that do not, lengths of 0 to 4 GiB, garbage data and sum item lists,
    globs, notifications in every transmission mode."""
    command = draw(st.sampled_from(sorted(REQUEST_TYPES)))
    fields = []
    for name, kind in REQUEST_TYPES[command].FIELDS:
        if kind == "u32":
            fields.append(draw(groups if name == "group" else u32))
        elif kind == "bytes":
            fields.append(draw(st.one_of(sum_payloads(), binaries)))
        else:
            fields.append(draw(_field_value("str").filter(lambda v: type(v) is str)))
    port = draw(st.one_of(st.sampled_from([int(p) for p in CncPort]), st.integers(0, 0xFFFF)))
    if command in (AdsCommand.READ, AdsCommand.ADD_DEVICE_NOTIFICATION) and draw(st.booleans()):
        port, *fields[:3] = draw(st.sampled_from(READABLE))  # an address that exists
    return [draw(invoke_ids), command, port, *fields]


@st.composite
def truncated(draw: st.DrawFn) -> bytes:
    """A frame cut short somewhere before its end."""
    raw = pack(draw(near_valid()))
    return raw[: draw(st.integers(0, len(raw) - 1))]


huge_headers = st.builds(
    lambda marker, length, tail: marker + length + tail,
    st.sampled_from([b"\xdd", b"\xdf", b"\xc6", b"\xdb", b"\xc7", b"\xc9"]),
    st.sampled_from([b"\xff\xff\xff\xff", b"\x7f\xff\xff\xff", b"\x00\x10\x00\x00"]),
    st.binary(max_size=16),
)
#: A request whose data field claims 4 GiB (bin 32) but carries a few bytes.
huge_fields = st.builds(
    lambda invoke_id, tail: b"\x96" + pack(invoke_id) + b"\x03\xcd\x02\x29\x00\x00"
    + b"\xc6\xff\xff\xff\xff" + tail,
    invoke_ids, st.binary(max_size=16),
)
deep_nesting = st.builds(lambda depth, head: head * depth + b"\x01",
                         st.integers(1, 3000), st.sampled_from([b"\x91", b"\x81\xa1k"]))
#: An array whose string fields are not UTF-8.
bad_utf8 = st.builds(
    lambda invoke_id, junk: b"\x94" + pack(invoke_id) + pack(0x100) + pack(553)
    + bytes([0xA0 | len(junk)]) + junk,
    invoke_ids, st.binary(min_size=1, max_size=8).filter(lambda b: not _is_utf8(b)),
)
#: msgpack maps with keys that are not strings (frames allow string keys only).
int_key_maps = st.builds(lambda k, v: pack([{k: v}]), st.integers(0, 100), values)


def _is_utf8(data: bytes) -> bool:
    try:
        data.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return True


garbage = st.one_of(
    truncated(),
    st.lists(values, max_size=10).map(pack),
    binaries,
    values.map(pack),
    huge_headers,
    huge_fields,
    deep_nesting,
    bad_utf8,
    int_key_maps,
)
#: Extra ZeroMQ parts in front of a frame (most messages have none).
prefixes = st.one_of(st.just([]), st.just([]), st.just([]),
                     st.lists(st.binary(max_size=12), min_size=1, max_size=3))


def _message(payload: st.SearchStrategy) -> st.SearchStrategy:
    return st.builds(lambda prefix, raw: [*prefix, raw], prefixes, payload)


def batches(size: int) -> st.SearchStrategy:
    """``size`` messages in a random order: half requests of the right shape with hostile
    content, a fifth near-valid ones, the rest garbage that the decoder refuses or drops.
    Fixed shares, because hypothesis's choice among branches drifts towards whatever it
    explored last."""
    requests, near = size // 2, size // 5

    def mix(a: list, b: list, c: list, rnd: object) -> list:
        batch = [*a, *b, *c]
        rnd.shuffle(batch)  # type: ignore[attr-defined]
        return batch

    return st.builds(
        mix,
        st.lists(_message(hostile_valid().map(pack)), min_size=requests, max_size=requests),
        st.lists(_message(near_valid().map(pack)), min_size=near, max_size=near),
        st.lists(_message(garbage), min_size=size - requests - near,
                 max_size=size - requests - near),
        st.randoms(use_true_random=False),
    )


# --------------------------------------------------------------------------- the rule


@dataclass(frozen=True)
class Expected:
    """The reply one message must get: behind ``prefix``, with ``invoke_id`` and
    ``command``; ``code`` is the ADS code when the decoder refuses the frame, None when
    the request is valid (then any code may come: it depends on the object)."""

    prefix: tuple[bytes, ...]
    invoke_id: int
    command: int
    code: int | None


def expected_reply(parts: list[bytes]) -> Expected | None:
    """The reply the service owes this message; None when it owes none."""
    raw = parts[-1]
    try:
        obj = msgpack.unpackb(raw, raw=False, strict_map_key=True)
    except Exception:  # not msgpack at all: nothing to answer, the id is unreadable
        obj = None
    readable = (type(obj) is list and obj and type(obj[0]) is int and 0 < obj[0] <= U32_MAX)
    try:
        request = decode_request(raw)
    except ProtocolError as exc:
        if exc.invoke_id is None:
            assert not readable, f"the decoder lost the invoke id of {obj!r:.200}"
            return None
        assert readable and exc.invoke_id == obj[0], (exc, obj)
        return Expected(tuple(parts[:-1]), exc.invoke_id, exc.command or 0, int(exc.code))
    assert readable
    return Expected(tuple(parts[:-1]), request.invoke_id, int(request.COMMAND), None)


@dataclass(frozen=True)
class Writable:
    """Where the catalog's writable objects are, to keep the fuzzer off them: their
    (port, group without the logical bit) and their handles (0xF005 offsets)."""

    groups: frozenset[tuple[int, int]]
    handles: frozenset[int]

    def touches(self, port: int, group: int, offset: int) -> bool:
        """True when a write to this address may reach a writable object."""
        if group == RIG.SYM_VALUE_BY_HANDLE:
            return offset in self.handles
        return (port, group & ~LOGICAL_BIT) in self.groups


def changes_the_machine(parts: list[bytes], writable: Writable) -> bool:
    """True for the few valid requests a fuzzer must not send because they would do what
    they ask: stop or reset the kernel, write a writable object (its own test writes
    every one of them)."""
    try:
        request = decode_request(parts[-1])
    except ProtocolError:
        return False
    match request:
        case WriteControlRequest():
            return request.ads_state in (AdsState.STOP, AdsState.RESET)
        case WriteRequest():
            return writable.touches(request.port, request.group, request.offset)
        case ReadWriteRequest() if request.group == RIG.SUM_WRITE:
            try:
                items = sums.decode_sum_write(request.offset, request.data)
            except (ValueError, struct.error):
                return False
            return any(writable.touches(request.port, i.group, i.offset) for i in items)
    return False


@dataclass
class BatchOutcome:
    """What one batch of messages got back."""

    replies: int = 0
    notifications: int = 0
    subscriptions: list[tuple[tuple[bytes, ...], int, int]] | None = None  # (prefix, port, handle)


def check_replies(expected: list[Expected], received: list[tuple[tuple[bytes, ...], list]]) -> None:
    """Every expected reply came exactly once, behind its prefix, with its command and,
    for refused frames, its code; nothing else came. ``received``: (prefix, reply)."""
    owed = Counter((e.prefix, e.invoke_id, e.command) for e in expected)
    got = Counter((prefix, r[0], r[1]) for prefix, r in received)
    missing, extra = owed - got, got - owed
    assert not missing and not extra, (
        f"lost replies: {list(missing.items())[:5]}; unexpected replies: {list(extra.items())[:5]}")
    codes: dict[tuple, Counter] = {}
    for prefix, r in received:
        codes.setdefault((prefix, r[0], r[1]), Counter())[r[2]] += 1
        if r[2]:
            assert len(r) == 4 and type(r[3]) is str and r[3], f"error reply without a message: {r}"
    for e in expected:
        if e.code is not None:
            bucket = codes[(e.prefix, e.invoke_id, e.command)]
            # 0x502: the client's mailbox was full (its requests over its rate): a defined
            # answer to any request, before it is decoded
            code = e.code if bucket[e.code] > 0 else AdsReturnCode.ROUTER_MAILBOXFULL
            assert bucket[code] > 0, (
                f"frame with invoke id {e.invoke_id} refused with {dict(bucket)}, not {e.code:#x}")
            bucket[code] -= 1


# --------------------------------------------------------------------------- half-sent


@dataclass(frozen=True)
class HalfSent:
    """A flood of ``connections`` raw TCP connections to one front end (``"ads"`` or
    ``"zmq"``), each sending the first ``sent`` bytes of a frame that announces
    ``announced`` bytes (after a ZeroMQ greeting; ``sent == 0``: the connection only)."""

    front_end: str
    connections: int
    announced: int
    sent: int

    def payload(self) -> bytes:
        """What each connection sends."""
        if self.front_end == "ads":
            return ads_half_frame(self.announced, self.announced - self.sent) if self.sent else b""
        if not self.sent:
            return zmtp_greeting()
        return zmtp_half_frame(self.announced, self.announced - self.sent)

    @property
    def must_close(self) -> bool:
        """Every connection of the flood must end without the client closing it: one
        holding an incomplete frame (closed by frame_timeout_s), and every raw ZeroMQ
        connection (it never answers the heartbeat's PING). An idle ADS connection
        within the cap may stay open."""
        return self.front_end == "zmq" or self.sent > 0


#: Frame sizes a flood announces: small, the ADS maximum, just under ZeroMQ's hard cap.
ANNOUNCED = [64, 4096, 65536, 1 << 20, 2_000_000]


@st.composite
def half_sent_floods(draw: st.DrawFn, max_connections: int) -> HalfSent:
    """Half-sent frames and connection floods, on either front end."""
    front_end = draw(st.sampled_from(["ads", "zmq"]))
    announced = draw(st.sampled_from(ANNOUNCED if front_end == "zmq" else ANNOUNCED[:4]))
    # announced >= 64: the AMS header (32 bytes) fits, the frame is incomplete
    sent = draw(st.one_of(st.just(0), st.integers(40, announced - 1),
                          st.just(announced - 1)))
    return HalfSent(front_end, draw(st.integers(1, max_connections)), announced, sent)
