"""Fuzz the ZeroMQ front end: malformed frames get a defined answer, the service survives.
Half-sent frames and connection floods on both front ends (raw TCP) are closed as the
limits say, while clients connected before are served.

10 000 frames in ``make test`` (the same ones every run: hypothesis derandomized), 100 000
in ``make soak`` (random). After every batch of 500, a fresh client reads the device info
and the ADS state, the kernel cycle is seen to advance and the log holds no traceback;
the service's resident memory is sampled and must stay within ``RSS_GROWTH_BOUND_KIB``.
"""

from __future__ import annotations

import math
import time
from collections import Counter
from pathlib import Path

import msgpack
import pytest
import zmq
from hypothesis import HealthCheck, given, settings

from cnc_objects.clients import Client
from cnc_objects.protocol.constants import AdsCommand, AdsState, CncPort
from cnc_objects.protocol.constants import ReservedIndexGroup as RIG
from cnc_objects.protocol.datatypes import STRING_ENCODING
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.frames import (
    AddNotificationRequest,
    BrowseRequest,
    DeleteNotificationRequest,
    ReadRequest,
    ReadStateRequest,
    ReadWriteRequest,
    WriteControlRequest,
)
from cnc_objects.testing import ServiceProcess, serving
from tests.limits.wire import limited_service
from tests.reliability import figures
from tests.reliability.floods import AdsProbe, Flood
from tests.reliability.health import (
    TICK_ADDRESS,
    RawConnection,
    Vitals,
    assert_well,
    vitals,
    wait_for_tick_after,
)
from tests.reliability.scale import Scale
from tests.reliability.wire_fuzz import (
    Expected,
    HalfSent,
    Writable,
    batches,
    changes_the_machine,
    check_replies,
    expected_reply,
    half_sent_floods,
)
from tests.support.resources import rss_kib

#: Frames per hypothesis example; a health check follows every ``Scale.wire_batch``.
FRAMES_PER_EXAMPLE = 50
#: How much the service's resident memory may grow over the whole fuzz run. It is a bound
#: on what stays allocated (caches, the allocator's arenas), independent of the number
#: of frames: 100 000 frames must stay within the same bound as 10 000.
RSS_GROWTH_BOUND_KIB = 32 * 1024
BATCH_TIMEOUT_S = 60.0  # all replies of one example (writes wait for a kernel cycle)
OVERSIZED_FRAME_BYTES = 3 << 20  # above the socket's MAXMSGSIZE (2 MiB)
NODE = "tests/reliability/test_wire_fuzz.py"
NOTIFICATIONS = "cnc_notifications_r"  # open notifications of all clients


@pytest.fixture(scope="module")
def service() -> ServiceProcess:
    """One service for the module (virtual clock; its kernel cycles every 1 ms)."""
    with serving() as running:
        yield running


@pytest.fixture(scope="module")
def writable(service: ServiceProcess) -> Writable:
    """Where the writable objects are (the fuzzer keeps off them)."""
    with Client(service.endpoint, timeout_s=10) as client:
        objects = [o for o in client.browse("*") if "w" in o.access]
        with RawConnection(service.endpoint) as conn:
            handles = set()
            for obj in objects:
                reply = conn.call(ReadWriteRequest, obj.port, RIG.SYM_HANDLE_BY_NAME, 0, 4,
                                  obj.name.encode(STRING_ENCODING) + b"\x00")
                assert reply[2] == 0, reply
                handles.add(int.from_bytes(reply[3], "little"))
    return Writable(frozenset((o.port, o.group & ~0x100000) for o in objects), frozenset(handles))


class FuzzRun:
    """Sends batches of messages on fresh connections and checks every reply; a health
    check (fresh client, cycle, log, RSS) follows every ``check_every`` frames."""

    def __init__(self, service: ServiceProcess, writable: Writable, check_every: int) -> None:
        self.service = service
        self.writable = writable
        self.check_every = check_every
        self.context = zmq.Context()
        self.sent = self.skipped = self.replies = self.subscriptions = self.checks = 0
        self.outcomes: Counter[str] = Counter()  # dropped / refused / request, per frame
        self.baseline: Vitals = vitals(service.endpoint)
        self.tick = self.baseline.tick
        self.rss_start_kib = self.rss_max_kib = rss_kib(service.process.pid)
        self._since_check = 0

    def close(self) -> None:
        self.context.destroy(linger=0)

    def batch(self, batch: list[list[bytes]]) -> None:
        """Send ``batch`` and check what comes back (one hypothesis example)."""
        batch = [m for m in batch if not changes_the_machine(m, self.writable)]
        self.skipped += FRAMES_PER_EXAMPLE - len(batch)
        verdicts = [expected_reply(m) for m in batch]
        self.outcomes.update("dropped" if e is None else "request" if e.code is None
                             else "refused" for e in verdicts)
        owed = [e for e in verdicts if e is not None]
        sock = self.context.socket(zmq.DEALER)
        sock.setsockopt(zmq.LINGER, 0)
        sock.connect(self.service.endpoint)
        try:
            for message in batch:
                sock.send_multipart(message)
            received = self._until_sentinel(sock, batch, owed)
            check_replies(owed, received)
            self._unsubscribe(sock, received, owed)
        finally:
            sock.close(linger=0)
        self.sent += len(batch)
        self.replies += len(received)
        self._since_check += len(batch)
        if self._since_check >= self.check_every:
            self.health_check()

    def _until_sentinel(self, sock: zmq.Socket, batch: list[list[bytes]],
                        owed: list[Expected]) -> list:
        """Every reply until the sentinels': one WriteControl RUN behind each envelope the
        batch used (no extra parts, and each set of extra parts, which the service takes
        for a client of its own, with a request rate of its own). A sentinel goes through
        its envelope's queue and the kernel's command queue behind every request of the
        batch on that envelope, so its reply comes after all of theirs."""
        used = {e.invoke_id for e in owed}
        free_ids = (i for i in range(0xFFFFFFFF, 0, -1) if i not in used)
        sentinels = {}
        for prefix in dict.fromkeys([(), *(tuple(m[:-1]) for m in batch)]):
            invoke_id = next(free_ids)
            sentinels[(prefix, invoke_id)] = True
            frame = WriteControlRequest(invoke_id, CncPort.COM, AdsState.RUN, 0, b"").encode()
            sock.send_multipart([*prefix, frame])
        received = []
        deadline = time.monotonic() + BATCH_TIMEOUT_S
        while sentinels:
            left_ms = int((deadline - time.monotonic()) * 1000)
            assert left_ms > 0 and sock.poll(left_ms), (
                f"no reply to {len(sentinels)} sentinels within {BATCH_TIMEOUT_S} s; "
                f"{len(received)} of {len(owed)} replies came")
            *prefix, raw = sock.recv_multipart()
            reply = msgpack.unpackb(raw, raw=False)
            if reply[:2] == [0, AdsCommand.DEVICE_NOTIFICATION]:
                continue  # a sample of a subscription the batch opened
            if sentinels.pop((tuple(prefix), reply[0]), None):
                assert reply[2] == 0, reply
                continue
            received.append((tuple(prefix), reply))
        return received

    def _unsubscribe(self, sock: zmq.Socket, received: list, owed: list[Expected]) -> None:
        """Delete the subscriptions the batch opened, from the envelope that opened them."""
        opened = [(prefix, r[3]) for prefix, r in received
                  if r[1] == AdsCommand.ADD_DEVICE_NOTIFICATION and r[2] == 0]
        self.subscriptions += len(opened)
        for k, (prefix, handle) in enumerate(opened):
            frame = DeleteNotificationRequest(k + 1, CncPort.COM, handle).encode()
            sock.send_multipart([*prefix, frame])
        done = 0
        deadline = time.monotonic() + BATCH_TIMEOUT_S
        while done < len(opened):
            left_ms = int((deadline - time.monotonic()) * 1000)
            assert left_ms > 0 and sock.poll(left_ms), "no reply to DeleteNotification"
            reply = msgpack.unpackb(sock.recv_multipart()[-1], raw=False)
            if reply[1] == AdsCommand.DELETE_DEVICE_NOTIFICATION:
                # 0x714: a DeleteNotification of the batch itself guessed the handle
                assert reply[2] in (0, AdsReturnCode.DEVICE_NOTIFYHNDINVALID), reply
                done += 1

    def health_check(self) -> None:
        """A fresh client reads correct answers; the cycle advances; RSS is sampled."""
        self._since_check = 0
        self.checks += 1
        self.tick = assert_well(self.service, self.tick, self.baseline).tick
        self.rss_max_kib = max(self.rss_max_kib, rss_kib(self.service.process.pid))


def test_malformed_frames_get_defined_answers_and_the_service_survives(
    service: ServiceProcess, writable: Writable, run_scale: Scale
) -> None:
    with Client(service.endpoint, timeout_s=10) as client:
        notifications_before = client.read(NOTIFICATIONS)
    run = FuzzRun(service, writable, run_scale.wire_batch)
    examples = math.ceil(run_scale.wire_frames / FRAMES_PER_EXAMPLE * 1.05)  # room for skips
    started = time.monotonic()
    try:
        @settings(max_examples=examples, derandomize=run_scale.name == "make test",
                  database=None, deadline=None, print_blob=True,
                  suppress_health_check=list(HealthCheck))
        @given(batches(FRAMES_PER_EXAMPLE))
        def fuzz(batch: list[list[bytes]]) -> None:
            run.batch(batch)

        fuzz()
        run.health_check()
    finally:
        run.close()
    elapsed_s = time.monotonic() - started
    with Client(service.endpoint, timeout_s=10) as client:  # every subscription was deleted
        assert client.read(NOTIFICATIONS) == notifications_before
    rss_end_kib = rss_kib(service.process.pid)
    growth_kib = rss_end_kib - run.rss_start_kib
    print(f"\nwire fuzz: {run.sent} frames ({dict(run.outcomes)}; {run.skipped} "
          "machine-changing ones left out), "
          f"{run.replies} replies, {run.subscriptions} subscriptions opened and deleted, "
          f"{run.checks} health checks, {elapsed_s:.1f} s; RSS {run.rss_start_kib} KiB at "
          f"start, {rss_end_kib} KiB at the end (max {run.rss_max_kib}, growth {growth_kib})")
    figures.record("malformed frames sent (each answered as the rule says)", f"{run.sent}", NODE)
    figures.record("replies checked / health checks", f"{run.replies} / {run.checks}", NODE)
    figures.record("service RSS at start / end / max of the fuzz",
                   f"{run.rss_start_kib // 1024} / {rss_end_kib // 1024} / "
                   f"{run.rss_max_kib // 1024} MiB", NODE)
    assert run.sent >= run_scale.wire_frames
    assert run.rss_max_kib - run.rss_start_kib < RSS_GROWTH_BOUND_KIB, (
        f"RSS grew by {(run.rss_max_kib - run.rss_start_kib) // 1024} MiB (bound "
        f"{RSS_GROWTH_BOUND_KIB // 1024} MiB)")


def test_an_oversized_frame_cuts_off_only_its_sender(service: ServiceProcess) -> None:
    """A frame above the size limit is not buffered: ZeroMQ drops the connection that
    sent it (MAXMSGSIZE); other clients are served throughout."""
    before = vitals(service.endpoint)
    rss_before_kib = rss_kib(service.process.pid)
    with RawConnection(service.endpoint) as bystander, RawConnection(service.endpoint) as sender:
        bystander.call(ReadRequest, *TICK_ADDRESS, 4)
        for _ in range(5):
            sender.sock.send(b"\x00" * OVERSIZED_FRAME_BYTES)
            assert bystander.call(ReadRequest, *TICK_ADDRESS, 4)[2] == 0
        # The sender's own connection was cut; its DEALER reconnects by itself and a
        # request after it is answered again.
        assert sender.call(ReadRequest, *TICK_ADDRESS, 4, timeout_s=20)[2] == 0
    assert_well(service, before.tick, before)
    growth_kib = rss_kib(service.process.pid) - rss_before_kib
    print(f"\n5 frames of {OVERSIZED_FRAME_BYTES >> 20} MiB: RSS grew by {growth_kib} KiB")
    assert growth_kib < RSS_GROWTH_BOUND_KIB


GLOB_STALL_PATTERN = "*" * 40 + "q"  # no object matches it
GLOB_REPLY_BOUND_S = 5.0


def test_a_glob_of_many_stars_is_answered_at_once(service: ServiceProcess) -> None:
    """A BROWSE pattern with many stars is answered in bounded time (it was a regex with
    one '.*' per star: twelve stars stalled the event loop, and with it the cycle, for
    minutes), and other clients are served meanwhile."""
    before = vitals(service.endpoint)
    with RawConnection(service.endpoint) as attacker:
        attacker.sock.send(BrowseRequest(7, CncPort.COM, GLOB_STALL_PATTERN).encode())
        now = vitals_within(service.endpoint, GLOB_REPLY_BOUND_S)
        reply = attacker.receive(GLOB_REPLY_BOUND_S)
    assert reply is not None and reply[:3] == [7, AdsCommand.BROWSE, 0] and reply[3] == []
    assert now.ads_state == AdsState.RUN
    wait_for_tick_after(service.endpoint, before.tick, GLOB_REPLY_BOUND_S)


def vitals_within(endpoint: str, timeout_s: float) -> Vitals:
    """``vitals`` with every reply due within ``timeout_s``."""
    with RawConnection(endpoint) as conn:
        reply = conn.call(ReadRequest, *TICK_ADDRESS, 4, timeout_s=timeout_s)
        state = conn.call(ReadStateRequest, CncPort.COM, timeout_s=timeout_s)
    return Vitals((), state[3], int.from_bytes(reply[3], "little"))



PER_CLIENT_NOTIFICATIONS = 1000  # default [limits] notifications_per_client


def test_extra_frame_parts_do_not_multiply_a_clients_allowance(service: ServiceProcess) -> None:
    """The per-client limits count a connection (its routing id), not an envelope: a
    client that puts extra parts before its frames (three prefixes here) still holds at
    most notifications_per_client (it held three times as many before)."""
    feed_override_r = (CncPort.COM, 0x120101, 0xA, 2)
    accepted = 0
    with RawConnection(service.endpoint) as conn:
        for invoke_id, prefix in enumerate(
                [b"a", b"b", b"c"] * PER_CLIENT_NOTIFICATIONS, start=1):
            frame = AddNotificationRequest(invoke_id, *feed_override_r, 4, 0, 1000).encode()
            conn.sock.send_multipart([prefix, frame])
            while True:  # samples of the subscriptions come in between
                reply = msgpack.unpackb(conn.sock.recv_multipart()[-1], raw=False)
                if reply[0] == invoke_id:
                    break
            accepted += reply[2] == 0
    assert accepted <= PER_CLIENT_NOTIFICATIONS


#: Limits of the half-sent fuzz: small, so that each example reaches them.
HALF_SENT_LIMITS = {"frame_timeout_s": 1.0, "connections_per_front_end": 16,
                    "receive_buffer_bytes_total": 4 << 20}
HALF_SENT_CLOSE_S = 30.0  # twice the timeout, on a loaded 2-core machine, with room
#: RSS while a flood holds its sockets: ZeroMQ's cap times its hard cap (16 x 2 MiB) and
#: the ADS budget (4 MiB), with room for the allocator.
HALF_SENT_RSS_BOUND_KIB = (16 * 2 + 4) * 1024 + 24 * 1024


def test_half_sent_frames_and_connection_floods_are_closed_as_the_limits_say(
    tmp_path: Path, run_scale: Scale
) -> None:
    """Each example floods one front end with connections that each send part of a frame
    (or nothing): every connection holding an incomplete frame, and every raw ZeroMQ
    connection (it never answers the heartbeat), is closed; RSS stays within the bound;
    clients of both front ends connected before are answered throughout."""
    with limited_service(tmp_path, ads=True, **HALF_SENT_LIMITS) as service:
        assert service.ads_address is not None and service.ams_net_id is not None
        zmq_address = service.endpoint.removeprefix("tcp://").rsplit(":", 1)
        rss_start_kib = rss_max_kib = rss_kib(service.process.pid)
        with RawConnection(service.endpoint) as zmq_probe:
            ads_probe = AdsProbe(service.ads_address, service.ams_net_id)
            zmq_probe.call(ReadRequest, *TICK_ADDRESS, 4)  # both probes hold a slot now
            assert ads_probe.read_device_info() == 0

            @settings(max_examples=run_scale.half_sent_examples,
                      derandomize=run_scale.name == "make test", database=None,
                      deadline=None, print_blob=True, suppress_health_check=list(HealthCheck))
            @given(half_sent_floods(24))
            def fuzz(flood: HalfSent) -> None:
                nonlocal rss_max_kib
                address = (service.ads_address if flood.front_end == "ads"
                           else (zmq_address[0], int(zmq_address[1])))
                with Flood(address, flood.connections, flood.payload()) as sockets:
                    rss_max_kib = max(rss_max_kib, rss_kib(service.process.pid))
                    assert zmq_probe.call(ReadRequest, *TICK_ADDRESS, 4)[2] == 0
                    assert ads_probe.read_device_info() == 0
                    if flood.must_close:
                        closed = sockets.wait_closed(flood.connections, HALF_SENT_CLOSE_S)
                        assert closed == flood.connections, (flood, closed)
                    rss_max_kib = max(rss_max_kib, rss_kib(service.process.pid))

            fuzz()
            ads_probe.close()
    growth_kib = rss_max_kib - rss_start_kib
    figures.record("half-sent frames / connection floods: RSS growth (max)",
                   f"{growth_kib >> 10} MiB over {run_scale.half_sent_examples} floods", NODE)
    assert growth_kib < HALF_SENT_RSS_BOUND_KIB, f"RSS grew by {growth_kib >> 10} MiB"
