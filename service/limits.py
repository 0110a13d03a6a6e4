"""Limits that keep one client from hurting the others: the ``[limits]`` configuration
table, and what the ZeroMQ front end does with a frame over the size limit.

Each limit is a key with a default (docs/limits.md lists them with what happens at the
limit and the figures measured):

- ``max_frame_bytes``: the longest ZeroMQ request frame served. A longer frame up to
  ``frame_hard_cap_bytes`` (twice the limit) is answered ADS 0x70B and dropped; a frame
  over the hard cap is never buffered: ZeroMQ (``MAXMSGSIZE``) closes that client's
  connection when it reads the frame's length (its DEALER reconnects by itself).
  ADS over AMS/TCP has its own ``[ads] max_frame_bytes``, with the same meaning on its
  wire (an AMS/TCP frame longer than that closes the connection).
- ``notifications_per_client`` and ``notifications_total``: AddDeviceNotification beyond
  either is answered 0x716 (no more handles).
- ``notification_max_bytes`` and ``notification_bytes_per_client``: the length one
  notification may have, and the lengths of all a client holds summed (what one pass
  of the notification hub reads for it); AddDeviceNotification beyond either is
  answered 0x717 (notification size too large) and subscribes nothing.
- ``send_hwm_messages`` / ``receive_hwm_messages``: ZeroMQ's high-water marks per client:
  replies and notifications queued for a client that does not read them (beyond: the
  reply is dropped, the notification counted as dropped), and requests read from the
  network but not yet served.
- ``requests_per_s_per_client``, ``request_burst`` and ``request_mailbox``: the token
  bucket of each client (``rate_limit``); requests over the rate wait in the client's
  mailbox, a full mailbox is answered ADS 0x502. The ADS front end stops reading a
  connection over the rate instead (TCP holds the rest).
- ``program_max_bytes`` and ``program_max_files``: the program store.
- ``output_max_files``, ``output_max_file_bytes``, ``output_max_total_bytes`` and
  ``output_queue_max_bytes``: the output area, the files the kernel writes (NC
  ``#MSG SAVE``, logs), and what may wait to be written (``output_writer``).
- ``connections_per_front_end``, ``frame_timeout_s`` and ``receive_buffer_bytes_total``:
  what open connections and frames that never complete may hold. A connection beyond
  the cap, a frame still incomplete after the timeout, and (ADS) a connection whose
  incomplete frame would take the receive buffers of all connections over the budget
  are closed and logged (throttled). ZeroMQ buffers incomplete frames inside libzmq,
  where no budget can be kept: there the bound is the cap times the frame hard cap
  (``zmq_receive_bound_bytes``), held at most ``frame_timeout_s``.
- ``jog_hold_timeout_s``: a pressed jog key not written TRUE again for this long is
  released; a key is released at once when its connection ends (``jog_holds``).
- ``opcua_*``: what OPC UA sessions, subscriptions, monitored items and publishes may
  hold (``opcua/limits.py``); ``connections_per_front_end`` and ``max_frame_bytes``
  bound OPC UA connections and messages too.
- ``idle_connection_s``: a full table closes the keyless connection idle longest (idle
  at least this long) for a newcomer; keyed connections keep their seats
  (``connection_limits``).

Handles (0xF003 handle by name) are not a per-client resource: a handle is the stable
number of an object, the same for every client, and releasing one frees nothing, so
there is nothing to limit.
"""

from __future__ import annotations

import msgpack
from pydantic import BaseModel, ConfigDict, Field

from cnc_objects.protocol.constants import (
    MAX_DATA_BYTES,
    PROGRAM_MAX_BYTES,
    PROGRAM_STORE_MAX_BYTES,
    STORE_MAX_TOTAL_BYTES,
)
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.frames import U32_MAX, encode_error

from .jog_holds import JOG_HOLD_TIMEOUT_S
from .kernel.nc.work_guard import IDLE_STEPS_MAX
from .kernel.step_clock import STEP_MAX_CYCLES
from .notifications import MAX_BYTES, MAX_BYTES_PER_CLIENT, NotificationLimits
from .rate_limit import RateLimiter

#: Room for a request's fields around its data (a Write's header is about 30 bytes).
FRAME_FIELDS_BYTES = 4096
#: The largest store the ``[limits]`` take (bytes): 1 TiB.
STORE_MAX_TOTAL_BYTES_LIMIT = 1 << 40
#: Bytes a client's waiting requests may hold (at least two frames of the largest size).
MAILBOX_BYTES = 16 << 20
#: How many bytes of a frame are looked at for its invoke id and command.
_HEAD_BYTES = 16


class LimitsConfig(BaseModel):
    """The ``[limits]`` table: what one client may cost the service."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    max_frame_bytes: int = Field(
        MAX_DATA_BYTES + FRAME_FIELDS_BYTES, ge=4096, le=64 << 20,
        description="longest ZeroMQ request frame served (bytes); longer ones up to twice "
        "this are answered ADS 0x70B and dropped, longer still close the client's connection "
        "before they are buffered",
    )
    notifications_per_client: int = Field(
        1000, ge=1, le=1_000_000,
        description="notifications (AddDeviceNotification) one client may hold; more: 0x716",
    )
    notifications_total: int = Field(
        20_000, ge=1, le=10_000_000,
        description="notifications all clients of both front ends may hold; more: 0x716",
    )
    notification_max_bytes: int = Field(
        MAX_BYTES, ge=1, le=MAX_DATA_BYTES,
        description="bytes one notification may carry (its AddDeviceNotification's "
        "length); longer: 0x717 (notification size too large)",
    )
    notification_bytes_per_client: int = Field(
        MAX_BYTES_PER_CLIENT, ge=1, le=1 << 30,
        description="bytes all notifications of one client may carry together (their "
        "lengths summed); one that would take it over: 0x717",
    )
    send_hwm_messages: int = Field(
        10_000, ge=1, le=1_000_000,
        description="ZeroMQ send high-water mark per client: replies and notification frames "
        "queued for a client that does not read; beyond it they are dropped",
    )
    receive_hwm_messages: int = Field(
        1000, ge=1, le=1_000_000,
        description="ZeroMQ receive high-water mark per client: requests read from the "
        "network and not yet served; beyond it ZeroMQ stops reading that client",
    )
    requests_per_s_per_client: float = Field(
        20_000.0, ge=0, le=10_000_000,
        description="requests per second one client may send on average (0: no limit); "
        "requests over it wait, a client's own order kept",
    )
    request_burst: int = Field(
        1000, ge=1, le=1_000_000,
        description="requests a client may send at once above its rate (its bucket's size)",
    )
    request_mailbox: int = Field(
        5000, ge=1, le=1_000_000,
        description="requests of a client over its rate that wait for their turn (at most "
        "16 MiB of them); more are answered ADS 0x502 (mailbox full)",
    )
    check_max_errors: int = Field(
        1000, ge=1, le=1_000_000,
        description="errors one syntax check keeps (listed in the channel, written to "
        "dec0<c>.sc); more are counted only, and the log says how many were left out",
    )
    decoder_idle_steps_max: int = Field(
        IDLE_STEPS_MAX, ge=1_000, le=1_000_000_000,
        description="the decoder's endless-program guard: steps of work (statements, calls, "
        "jumps, lines without a block) without a single block before the program ends "
        "with error 20226 (a few seconds of decoding at the default)",
    )
    step_max_cycles: int = Field(
        STEP_MAX_CYCLES, ge=1, le=10_000_000,
        description="cycles one write of cnc_cycle_step_w may grant (--clock step); the "
        "write's reply waits for all of them; more (or 0) are answered ADS 0x706",
    )
    alarm_history_max: int = Field(
        32, ge=1, le=1000,
        description="alarms the history keeps (the last ones raised, in any state); older "
        "ones leave it. Each is a slot of objects (alarm_history[k]): at most 1000",
    )
    alarm_active_max: int = Field(
        100, ge=1, le=100_000,
        description="alarms the active list holds; one more clears the oldest (logged)",
    )
    program_max_bytes: int = Field(
        PROGRAM_STORE_MAX_BYTES, ge=1, le=STORE_MAX_TOTAL_BYTES_LIMIT,
        description="largest program the store takes (bytes; a program larger than a frame "
        "goes in chunks, docs/limits.md); larger: 0x705, the upload is abandoned",
    )
    store_max_total_bytes: int = Field(
        STORE_MAX_TOTAL_BYTES, ge=1, le=STORE_MAX_TOTAL_BYTES_LIMIT,
        description="bytes all programs of the store hold together, uploads in progress "
        "included; an upload beyond: 0x70A, the upload is abandoned",
    )
    program_max_files: int = Field(
        1000, ge=1, le=1_000_000,
        description="files the program store holds; an upload of one more: 0x70A",
    )
    output_max_files: int = Field(
        1000, ge=1, le=1_000_000,
        description="files the output area holds; an NC program that would create one more "
        "(#MSG SAVE, a cycle's result file) stops with NC error 20533 naming this key",
    )
    output_max_file_bytes: int = Field(
        PROGRAM_MAX_BYTES, ge=4096, le=PROGRAM_MAX_BYTES,
        description="bytes one file of the output area may hold (at most what one download "
        "carries); an NC program's write beyond: NC error 20533; a kernel error log keeps "
        "its newest lines",
    )
    output_max_total_bytes: int = Field(
        64 << 20, ge=4096, le=1 << 40,
        description="bytes all files of the output area may hold together; an NC program's "
        "write beyond: NC error 20533",
    )
    output_queue_max_bytes: int = Field(
        4 << 20, ge=1 << 20, le=1 << 30,
        description="bytes the kernel's file writes may queue for the writer thread (128 "
        "more per write); an NC program's write beyond: NC error 20533, a kernel log line "
        "beyond is dropped (logged, throttled)",
    )

    connections_per_front_end: int = Field(
        64, ge=1, le=100_000,
        description="open connections each front end (ZeroMQ, ADS) serves at once; one "
        "more is closed at once (logged)",
    )
    jog_hold_timeout_s: float = Field(
        JOG_HOLD_TIMEOUT_S, ge=0, le=3600,
        description="seconds a pressed jog key (manual_jog_plus_w/minus_w TRUE) holds "
        "without being written TRUE again; then it is released (0: only when its "
        "connection ends)",
    )
    idle_connection_s: float = Field(
        5.0, ge=0, le=86_400,
        description="seconds without a request after which a keyless connection (no CURVE "
        "key, no ADS route) gives its seat to a newcomer when the table is full; keyed "
        "ones never do",
    )
    frame_timeout_s: float = Field(
        10.0, gt=0, le=3600,
        description="seconds a frame may take from its first byte to its last; a "
        "connection with a frame incomplete for longer is closed (logged)",
    )
    receive_buffer_bytes_total: int = Field(
        32 << 20, ge=1 << 20, le=16 << 30,
        description="bytes of incomplete frames all ADS connections may hold together; "
        "the connection that would take it over is closed (logged)",
    )

    opcua_sessions: int = Field(
        32, ge=1, le=10_000,
        description="OPC UA sessions open at once (created or activated, all clients); "
        "CreateSession beyond: Bad_TooManySessions",
    )
    opcua_activation_timeout_s: float = Field(
        10.0, gt=0, le=3600,
        description="seconds an OPC UA connection may stay without an activated session "
        "(a half-open secure channel); then it is closed",
    )
    opcua_subscriptions_per_session: int = Field(
        20, ge=1, le=10_000,
        description="OPC UA subscriptions one session may hold; CreateSubscription beyond: "
        "Bad_TooManySubscriptions",
    )
    opcua_subscriptions_total: int = Field(
        200, ge=1, le=100_000,
        description="OPC UA subscriptions of all sessions; CreateSubscription beyond: "
        "Bad_TooManySubscriptions",
    )
    opcua_monitored_items_per_session: int = Field(
        2000, ge=1, le=1_000_000,
        description="OPC UA monitored items one session may hold; each item beyond: "
        "Bad_TooManyMonitoredItems",
    )
    opcua_monitored_items_total: int = Field(
        10_000, ge=1, le=10_000_000,
        description="OPC UA monitored items of all sessions; each item beyond: "
        "Bad_TooManyMonitoredItems",
    )
    opcua_queue_size_max: int = Field(
        100, ge=1, le=100_000,
        description="values one OPC UA monitored item may queue between publishes; a larger "
        "requested QueueSize is revised down to it (the oldest value is dropped)",
    )
    opcua_notifications_per_publish: int = Field(
        10_000, ge=1, le=1_000_000,
        description="data changes in one OPC UA PublishResponse (or the subscription's "
        "MaxNotificationsPerPublish when smaller); the rest go in the next ones",
    )

    @property
    def frame_hard_cap_bytes(self) -> int:
        """ZeroMQ's MAXMSGSIZE: frames over it are never buffered (the peer is cut off)."""
        return frame_hard_cap_bytes(self.max_frame_bytes)

    @property
    def zmq_receive_bound_bytes(self) -> int:
        """What incomplete ZeroMQ frames can hold at most (inside libzmq, which allocates
        a frame's announced size): every connection of the cap with one frame just
        under the hard cap."""
        return self.connections_per_front_end * self.frame_hard_cap_bytes

    @property
    def mailbox_bytes(self) -> int:
        """Bytes a client's waiting requests may hold (besides ``request_mailbox``)."""
        return max(MAILBOX_BYTES, 2 * self.max_frame_bytes)


def rate_limiter(limits: LimitsConfig) -> RateLimiter | None:
    """The token buckets of ``limits`` for one front end; None without a rate limit."""
    if limits.requests_per_s_per_client <= 0:
        return None
    return RateLimiter(limits.requests_per_s_per_client, limits.request_burst,
                       limits.request_mailbox, limits.mailbox_bytes)


def notification_limits(limits: LimitsConfig) -> NotificationLimits:
    """What the notification hub takes from ``limits``."""
    return NotificationLimits(limits.notifications_per_client, limits.notifications_total,
                              limits.notification_max_bytes,
                              limits.notification_bytes_per_client)


def frame_hard_cap_bytes(max_frame_bytes: int) -> int:
    """The hard cap on a ZeroMQ frame for a frame limit: twice the limit."""
    return 2 * max_frame_bytes


def request_head(raw: bytes) -> tuple[int, int] | None:
    """(invoke id, command) of a request frame, read from its first bytes only (the
    frame is never unpacked whole); None when they do not name a valid invoke id."""
    unpacker = msgpack.Unpacker(raw=False)
    unpacker.feed(raw[:_HEAD_BYTES])
    try:
        if unpacker.read_array_header() < 2:
            return None
        invoke_id, command = unpacker.unpack(), unpacker.unpack()
    except (ValueError, msgpack.UnpackException, msgpack.OutOfData, TypeError):
        return None
    if type(invoke_id) is not int or not 0 < invoke_id <= U32_MAX or type(command) is not int:
        return None
    return invoke_id, command


def oversized_reply(raw: bytes, max_frame_bytes: int) -> bytes | None:
    """The 0x70B reply to a frame over ``max_frame_bytes``; None when its head does not
    name an invoke id (the frame is then dropped unanswered, as any unreadable frame)."""
    head = request_head(raw)
    if head is None:
        return None
    return encode_error(
        *head, AdsReturnCode.DEVICE_INVALIDPARM,
        f"frame of {len(raw)} bytes exceeds the limit of {max_frame_bytes} bytes "
        "([limits] max_frame_bytes); not served",
    )
