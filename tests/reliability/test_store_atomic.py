"""The program store is atomic: a service stopped (SIGTERM) or killed (SIGKILL) while
programs are uploaded, or while a program runs and writes its message file, leaves every
file whole, the old version or the new, never half of one; a service started again on
the same store serves what is on disk.

The moment is chosen at random (a fixed seed in ``make test``) among the uploads: the
signal goes out when the service has logged the k-th upload, with more uploads queued
behind it, so that it lands while the service is writing one.
"""

from __future__ import annotations

import random
import re
import signal
from pathlib import Path

import msgpack
import pytest

from cnc_objects.clients import Client
from cnc_objects.protocol.constants import PROGRAM_STORE_GROUP, CncPort
from cnc_objects.protocol.constants import ProgramStoreOffset as Op
from cnc_objects.protocol.values import ChannelState
from cnc_objects.testing import ServiceProcess, start_service
from tests.reliability import figures
from tests.reliability.health import RawConnection, poll_until
from tests.reliability.scale import Scale, soak

SEED = 2111  # the moments of `make test`
PROGRAM = "big.nc"
PROGRAM_LINES = 20_000  # about 900 kB, below the store's 1 MB limit: a write takes a while
QUEUED_UPLOADS = 6  # clients uploading at once, so that one is being written at the signal
UPLOADED = re.compile(rf"program '{re.escape(PROGRAM)}' uploaded")
EXIT_TIMEOUT_S = 20.0
CLIENT_TIMEOUT_S = 30.0
NODE = "tests/reliability/test_store_atomic.py"


def version(n: int) -> bytes:
    """Version ``n`` of the big program: every line names the version, so that a file
    made of two versions, or cut short, is told apart from both."""
    lines = [f"N{k} G1 X{k % 100}.{n} Y{n} F6000 ; version {n} line {k}"
             for k in range(PROGRAM_LINES)]
    return ("\n".join(lines) + "\nM30\n").encode()


VERSIONS = (version(1), version(2))


def upload_frame(invoke_id: int, data: bytes) -> bytes:
    """The Write that uploads ``data`` as PROGRAM (name, NUL, content)."""
    return msgpack.packb([invoke_id, 3, CncPort.COM, PROGRAM_STORE_GROUP, Op.UPLOAD,
                          PROGRAM.encode() + b"\x00" + data], use_bin_type=True)


def stop(service: ServiceProcess, sig: signal.Signals) -> int:
    """Send ``sig`` and return the exit code (the log is complete afterwards)."""
    service.process.send_signal(sig)
    code = service.process.wait(EXIT_TIMEOUT_S)
    service.stop()  # joins the log; the process has ended already
    return code


def count_uploads(service: ServiceProcess) -> int:
    return sum(1 for line in service.log if UPLOADED.search(line))


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
def test_a_signal_during_uploads_leaves_the_old_or_the_new_file(
    tmp_path: Path, run_scale: Scale, sig: signal.Signals
) -> None:
    store = tmp_path / "store"
    seed = random.SystemRandom().randrange(2**32) if soak() else SEED
    rnd = random.Random(seed)
    outcomes = []
    leftovers = 0
    for round_ in range(run_scale.store_kills):
        service = start_service(program_dir=store)
        try:
            if round_ == 0:
                with RawConnection(service.endpoint) as conn:
                    conn.sock.send(upload_frame(1, VERSIONS[0]))
                    assert conn.receive(CLIENT_TIMEOUT_S)[2] == 0
            # several clients upload at once (one client's uploads beyond its rate would
            # wait in its mailbox, which holds one frame of the largest size)
            uploaders = [RawConnection(service.endpoint) for _ in range(QUEUED_UPLOADS)]
            try:
                for k, conn in enumerate(uploaders):
                    conn.sock.send(upload_frame(k + 2, VERSIONS[(round_ + k + 1) % 2]))
                target = rnd.randint(1, QUEUED_UPLOADS - 1) + (round_ == 0)
                poll_until(lambda: count_uploads(service), lambda n: n >= target,
                           CLIENT_TIMEOUT_S, f"upload number {target}")
                code = stop(service, sig)
            finally:
                for conn in uploaders:
                    conn.close()
        finally:
            if service.process.poll() is None:
                service.process.kill()
                service.stop()
        assert code == (0 if sig == signal.SIGTERM else -signal.SIGKILL), service.log_text
        on_disk = (store / PROGRAM).read_bytes()
        assert on_disk in VERSIONS, (
            f"{PROGRAM} is neither version after {sig.name}: {len(on_disk)} bytes, "
            f"starting {on_disk[:60]!r}")
        outcomes.append(VERSIONS.index(on_disk) + 1)
        leftovers = len(list(store.glob(".*")))  # temporary files of cut-off uploads
    # A service started on the same store serves the file that is on disk.
    service = start_service(program_dir=store)
    try:
        with Client(service.endpoint, timeout_s=CLIENT_TIMEOUT_S) as client:
            assert client.download(PROGRAM) == (store / PROGRAM).read_bytes()
            assert [p.name for p in client.programs()] == [PROGRAM]
    finally:
        assert service.stop() == 0, service.log_text
    print(f"\n{run_scale.store_kills} x {sig.name} during uploads (seed {seed}): versions on disk "
          f"{outcomes}; hidden temporary files left: {leftovers}")
    figures.record(f"{sig.name} during uploads of a 900 kB program",
                   f"{run_scale.store_kills} times, the file whole each time "
                   f"(versions {outcomes}); {leftovers} hidden temp files left", NODE)


RUN_LOG = "run-log.txt"
LOOP_PROGRAM = b"""; a loop that moves and writes a line per pass into run-log.txt
#VAR
V.L.I = 0
#ENDVAR
#FILE NAME [MSG="run-log.txt"]
$WHILE V.L.I < 100000
V.L.I = V.L.I + 1
#MSG SAVE ["pass %d of the loop", V.L.I]
G91 G1 X1 F60000
G1 X-1
$ENDWHILE
M30
"""
LOG_LINE = re.compile(rb"pass (\d+) of the loop")
LINES_BEFORE_SIGNAL = 50


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
def test_a_signal_during_a_run_leaves_the_store_whole(
    tmp_path: Path, run_scale: Scale, sig: signal.Signals
) -> None:
    store = tmp_path / "store"
    outputs = tmp_path / "store-output"  # the output area beside a --program-dir store
    passes = []
    for _ in range(run_scale.store_kills):
        # --speed 1: kernel time at wall pace, so the program is running at the signal
        service = start_service("--speed", "1", program_dir=store)
        try:
            with Client(service.endpoint, timeout_s=CLIENT_TIMEOUT_S) as client:
                client.upload("loop.nc", LOOP_PROGRAM)
                client.run_program("loop.nc")
                poll_until(lambda: _log_lines(client), lambda n: n >= LINES_BEFORE_SIGNAL,
                           CLIENT_TIMEOUT_S, f"{LINES_BEFORE_SIGNAL} lines in {RUN_LOG}")
                assert client.read("ch1.mc_active_state_r") == ChannelState.ACTIVE
            code = stop(service, sig)
        finally:
            if service.process.poll() is None:
                service.process.kill()
                service.stop()
        assert code == (0 if sig == signal.SIGTERM else -signal.SIGKILL), service.log_text
        assert (store / "loop.nc").read_bytes() == LOOP_PROGRAM
        assert sorted(p.name for p in store.iterdir()) == ["loop.nc"]  # the log is not here
        lines = (outputs / RUN_LOG).read_bytes().split(b"\n")
        assert lines[-1] == b"", "the message file ends inside a line"
        matches = [LOG_LINE.fullmatch(line) for line in lines[:-1]]
        assert all(matches), "a line of the message file is not whole"
        numbers = [int(m.group(1)) for m in matches]  # type: ignore[union-attr]
        assert numbers == list(range(1, len(numbers) + 1)), "lines lost or doubled"
        passes.append(len(numbers))
        (outputs / RUN_LOG).unlink()
    # started again on the same store, the program runs
    service = start_service(program_dir=store)
    try:
        with Client(service.endpoint, timeout_s=CLIENT_TIMEOUT_S) as client:
            client.run_program("loop.nc")
            client.reset()
    finally:
        assert service.stop() == 0, service.log_text
    print(f"\n{run_scale.store_kills} x {sig.name} during a run: message file whole, "
          f"{passes} lines")
    figures.record(f"{sig.name} during a run writing its message file",
                   f"{run_scale.store_kills} times, program and message file whole", NODE)


def _log_lines(client: Client) -> int:
    """Lines of RUN_LOG so far (0 before it exists)."""
    files = {p.name: p.size_bytes for p in client.outputs()}
    if RUN_LOG not in files:
        return 0
    return client.download_output(RUN_LOG).count(b"\n")
