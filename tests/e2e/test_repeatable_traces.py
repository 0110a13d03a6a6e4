"""Traces that repeat (issue 37): with ``--samples repeatable`` every subscription is
sampled at its due cycles of kernel time and no sample is dropped, so the same program
with the same subscriptions gives the same samples, cycle for cycle, in every run and on
``--clock virtual``, ``virtual-step`` and ``step``; a reader that does not read holds the
kernel (a bounded queue) instead of losing samples."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
import zmq

from cnc_objects.clients import Client
from cnc_objects.protocol.constants import AdsCommand, TransmissionMode
from cnc_objects.protocol.filetime import filetime_from_unix_ns
from cnc_objects.protocol.frames import (
    Notification,
    RawSample,
    Response,
    decode_incoming,
    encode_request,
)
from cnc_objects.testing import serving
from cnc_objects.testing.trace import TraceRecorder, TraceRow

ROOT = Path(__file__).resolve().parents[2]
POCKET = ROOT / "docs/examples/pocket-la-on.nc"  # LA_ON, arcs and lines: 32 s of machining


def trace_of(clock: str, program: Path = POCKET) -> list[TraceRow]:
    """The trace of ``program`` on a fresh service on ``clock`` with repeatable samples:
    positions and path velocity every 10 ms, block number and state on change (5 ms)."""
    with serving("--clock", clock, "--samples", "repeatable") as service:
        recorder = TraceRecorder(service.endpoint, stepping=clock == "step")
        recorder.watch(["ch1.ax1.command_position_acs", "ch1.ax2.command_position_acs",
                        "ch1.actual_path_velocity"], cycle_ms=10)
        recorder.watch(["ch1.actual_block_number", "ch1.mc_active_state_r"], cycle_ms=5,
                       on_change=True)
        return recorder.run(program)


def test_the_same_run_gives_the_same_trace_every_time() -> None:
    first = trace_of("virtual")
    assert first == trace_of("virtual")
    # every 10 ms of the run is in it (nothing dropped), from START to the end
    positions = [r.kernel_ns for r in first if r.name == "ch1.ax1.command_position_acs"]
    assert positions == list(range(positions[0], positions[-1] + 1, 10_000_000))
    assert positions[-1] - positions[0] > 30_000_000_000
    states = [r for r in first if r.name == "ch1.mc_active_state_r"]
    assert states[1].value == 4 and states[1].kernel_ns == states[0].kernel_ns + 5_000_000


def test_a_trace_is_the_same_on_every_clock() -> None:
    event_speed = trace_of("virtual")
    assert trace_of("virtual-step") == event_speed
    assert trace_of("step") == event_speed


#: The slow reader's subscriptions, every cycle (1 ms): the kernel time, and texts of 256
#: bytes that fill the queues (ZeroMQ's and the sockets') in a few seconds of kernel time.
SLOW_OBJECTS = ["cnc_kernel_time_r", *(f"ch1.mc_message_{k}_text_r" for k in (1, 2, 3))]
SLOW_MOVE = "G90 G1 X200 F600"  # twenty seconds of kernel time
SLOW_MOVE_NS = 20_000_000_000


def test_a_reader_that_does_not_read_holds_the_kernel_and_loses_nothing(
        tmp_path: Path) -> None:
    """A client subscribes every cycle and then reads nothing: once its queues are full
    the kernel stops (its kernel time stands while the move has not ended) instead of
    dropping samples; when the client reads again, every cycle's sample comes, in order,
    with no gap in the sequence numbers."""
    config = tmp_path / "small-queues.toml"
    config.write_text("[limits]\nsend_hwm_messages = 4\n")
    with serving("--clock", "virtual", "--samples", "repeatable",
                 "--config", str(config)) as service, Client(service.endpoint) as c:
        reader = zmq.Context.instance().socket(zmq.DEALER)
        reader.setsockopt(zmq.LINGER, 0)
        reader.setsockopt(zmq.RCVHWM, 1)
        reader.setsockopt(zmq.RCVBUF, 4096)
        reader.connect(service.endpoint)
        try:
            for invoke_id, name in enumerate(SLOW_OBJECTS, 1):
                info = c.describe(name)
                reader.send(encode_request(
                    invoke_id, AdsCommand.ADD_DEVICE_NOTIFICATION, info.port,
                    (info.group, info.offset, info.length,
                     int(TransmissionMode.SERVER_CYCLE), 0, 1)))
            handles, early = _handles(reader, len(SLOW_OBJECTS))
            c.mdi(SLOW_MOVE)
            stood_ns = _kernel_time_once_it_stands(c)
            assert c.read("ch1.mc_active_state_r") == 4  # ACTIVE: held, not ended
            assert stood_ns < SLOW_MOVE_NS
            samples = early + _read_until(reader, handles[0], SLOW_MOVE_NS)
        finally:
            reader.close()
    step = filetime_from_unix_ns(1_000_000) - filetime_from_unix_ns(0)
    for handle in handles:
        mine = [s for s in samples if s.handle == handle]
        assert [s.sequence for s in mine] == list(range(1, len(mine) + 1))  # no gap
        stamps = [s.timestamp for s in mine]  # kernel time: every cycle, in order
        assert stamps == list(range(stamps[0], stamps[0] + step * len(stamps), step))
    assert len(samples) > 4 * SLOW_MOVE_NS // 1_000_000


def _handles(reader: zmq.Socket[bytes], count: int) -> tuple[list[int], list[RawSample]]:
    """The handles of the first ``count`` replies, in invoke-id order, and the samples
    that came meanwhile."""
    handles: dict[int, int] = {}
    samples: list[RawSample] = []
    while len(handles) < count:
        message = decode_incoming(reader.recv())
        if isinstance(message, Response):
            assert message.result == 0, message
            handles[message.invoke_id] = message.fields[0]
        else:
            samples.extend(message.samples)
    return [handles[k] for k in sorted(handles)], samples


def _kernel_time_once_it_stands(c: Client, timeout_s: float = 60.0) -> int:
    """The kernel time (ns) once it no longer advances between reads 50 ms apart."""
    deadline = time.monotonic() + timeout_s
    last = -1
    while time.monotonic() < deadline:
        now = round(c.read("cnc_kernel_time_r") * 1e9)
        if now == last:
            return now
        last = now
        time.sleep(0.05)  # the interval the kernel time must stand still over
    raise AssertionError(f"the kernel time did not stand still within {timeout_s} s "
                         f"(last {last} ns): the kernel did not wait for the reader")


def _read_until(reader: zmq.Socket[bytes], handle: int, kernel_ns: int) -> list[RawSample]:
    """Every sample the reader's socket holds, read until one of ``handle`` at
    ``kernel_ns`` or later."""
    end = filetime_from_unix_ns(kernel_ns)
    samples: list[RawSample] = []
    last = 0
    reader.setsockopt(zmq.RCVTIMEO, 60_000)
    while last < end:
        message = decode_incoming(reader.recv())
        if isinstance(message, Notification):
            samples.extend(message.samples)
            last = max([last, *(s.timestamp for s in message.samples if s.handle == handle)])
    return samples


def test_repeatable_samples_are_refused_on_the_realtime_clock() -> None:
    """The realtime clock cannot wait for a reader: the service says so and does not
    start."""
    with pytest.raises(RuntimeError, match="repeatable samples .* need --clock virtual"):
        with serving("--clock", "realtime", "--samples", "repeatable"):
            pass


def test_a_bad_samples_key_is_refused_naming_it(tmp_path: Path) -> None:
    config = tmp_path / "bad.toml"
    config.write_text('[clock]\nsamples = "every"\n')
    with pytest.raises(RuntimeError, match=r"clock\.samples"):
        with serving("--config", str(config)):
            pass


def test_the_configuration_key_selects_repeatable_samples(tmp_path: Path) -> None:
    config = tmp_path / "repeatable.toml"
    config.write_text('[clock]\nsamples = "repeatable"\n')
    with serving("--config", str(config)) as service:
        assert "repeatable samples" in service.wait_for_log(r"listening on ")
