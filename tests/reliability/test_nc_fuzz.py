"""Fuzz NC programs: mutants of every example program go through the syntax check and a
run; the channel reports an error or finishes (or, for an endless loop, is RESET after a
bounded time); no kernel thread dies and the service answers afterwards. Mutants that
write files (``#FILE NAME`` naming a stored program, ``#MSG SAVE [EXCLUSIVE]``) leave the
program store as it was: every byte of every stored file is the same afterwards.

The mutants are the same every ``make test`` run (a fixed seed); ``make soak`` draws
a new seed and prints it, so that a failure can be reproduced (``CNC_NC_SEED=<seed>``).
A few mutants also go through the CLI: ``cnc check`` and ``cnc run --wait --wait-timeout``.
"""

from __future__ import annotations

import os
import random
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import pytest

from cnc_objects.clients import AdsError, AdsTimeoutError, ChannelError, Client, NoReplyError
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.values import ChannelState
from cnc_objects.testing import ServiceProcess, serving, start_service, wait_for
from tests.reliability import figures
from tests.reliability.health import (
    assert_well,
    fault_records,
    vitals,
    wait_for_tick_after,
)
from tests.reliability.nc_mutations import KEEP, Mutant, mutate, sources, support_files
from tests.reliability.scale import Scale

QUICK_SEED = 20_211  # the mutants of `make test`
CHECK_TIMEOUT_S = 3.0  # a syntax check that has not ended is RESET (endless loops)
RUN_TIMEOUT_S = 3.0  # a run that has not ended is RESET (endless loops with motion)
STOP_TIMEOUT_S = 10.0  # after RESET the channel must stop working within this
# one request (a busy machine; the decoder may be busy too). A START is answered when the
# kernel has applied it, also while the run's first cycle waits for the decoder (an idle
# endless loop, $WHILE 1 V.L.X = .., once held the reply until ENDLESS_LOOP: 14-21 s)
CLIENT_TIMEOUT_S = 20.0
#: What the service may answer when it refuses to start a mutant (ADS codes).
START_REFUSALS = {
    AdsReturnCode.DEVICE_NOTFOUND,  # the program is not stored (never, here)
    AdsReturnCode.DEVICE_INVALIDDATA,  # a name the store refuses (never, here)
    AdsReturnCode.DEVICE_NOTREADY,  # the channel is not ready
}
WORKING = (ChannelState.ACTIVE, ChannelState.HOLD)
NODE = "tests/reliability/test_nc_fuzz.py"


@pytest.fixture(scope="module")
def service() -> ServiceProcess:
    """One service for the module, with the files the examples call in its store."""
    with serving() as running:
        with Client(running.endpoint, timeout_s=CLIENT_TIMEOUT_S) as client:
            for path in support_files():
                client.upload(path.name, path.read_bytes())
            client.upload(*KEEP)
        yield running


def stored(client: Client) -> dict[str, bytes]:
    """Every file of the program store with its content."""
    return {p.name: client.download(p.name) for p in client.programs()}


def seed() -> int:
    """The seed of this run: fixed for make test, new for make soak (or CNC_NC_SEED)."""
    if "CNC_NC_SEED" in os.environ:
        return int(os.environ["CNC_NC_SEED"])
    from tests.reliability.scale import soak

    return random.SystemRandom().randrange(2**32) if soak() else QUICK_SEED


def mutants(count: int, rnd: random.Random) -> list[Mutant]:
    """``count`` mutants, taken from the sources in turn."""
    paths = sources()
    assert paths, "no example programs found"
    return [mutate(k, paths[k % len(paths)], rnd) for k in range(count)]


def stop_if_working(client: Client) -> None:
    """RESET a channel that still works; wait (bounded) until it has stopped."""
    if client.read("ch1.mc_active_state_r") in WORKING:
        client.reset()
    wait_for(client, "ch1.mc_active_state_r", lambda state: state not in WORKING,
             timeout_s=STOP_TIMEOUT_S)
    client.reset_to_standard()  # out of ERROR; standard execution mode


def check(client: Client, mutant: Mutant) -> str:
    """Syntax check ``mutant``; the outcome's name. Anything but a result, a refusal with
    a defined code or the check's own timeout fails the test."""
    try:
        result = client.syntax_check(mutant.name, timeout_s=CHECK_TIMEOUT_S)
    except NoReplyError:
        raise
    except AdsTimeoutError as exc:
        assert "did not end within" in str(exc), exc
        return "check: timeout, RESET"
    except ChannelError:
        return "check: start failed (ERROR)"
    except AdsError as exc:
        assert exc.code in START_REFUSALS, f"{mutant}: {exc}"
        return f"check: refused {exc.code:#x}"
    finally:
        stop_if_working(client)
    if result.aborted is not None:
        return "check: aborted"
    return "check: clean" if result.clean else "check: errors"


def run(client: Client, mutant: Mutant) -> str:
    """Run ``mutant``; the outcome's name (READY, ERROR, or RESET after the timeout)."""
    try:
        client.run_program(mutant.name)
        client.wait_program(timeout_s=RUN_TIMEOUT_S)
    except NoReplyError:
        raise
    except ChannelError as exc:
        assert str(exc), mutant
        return "run: ERROR"
    except AdsTimeoutError as exc:
        assert "still" in str(exc), exc
        return "run: timeout, RESET"
    except AdsError as exc:
        assert exc.code in START_REFUSALS, f"{mutant}: {exc}"
        return f"run: refused {exc.code:#x}"
    finally:
        stop_if_working(client)
    return "run: READY"


def test_mutated_programs_end_in_a_defined_state(service: ServiceProcess, run_scale: Scale) -> None:
    used_seed = seed()
    rnd = random.Random(used_seed)
    before = vitals(service.endpoint)
    outcomes: Counter[str] = Counter()
    endless = writes = 0
    started = time.monotonic()
    print(f"\nNC fuzz: seed {used_seed} (CNC_NC_SEED={used_seed} makes the same mutants)")
    with Client(service.endpoint, timeout_s=CLIENT_TIMEOUT_S) as client:
        store_before = stored(client)
        assert KEEP[0] in store_before
        for mutant in mutants(run_scale.nc_mutations, rnd):
            client.upload(mutant.name, mutant.data)
            try:
                outcomes[check(client, mutant)] += 1
                outcomes[run(client, mutant)] += 1
            except (AssertionError, AdsError) as exc:
                raise AssertionError(f"seed {used_seed}: {mutant.name} from {mutant.source} "
                                     f"({'; '.join(mutant.changes)}): {exc!r}") from None
            endless += mutant.endless
            writes += any("#MSG SAVE" in change for change in mutant.changes)
            client.delete_program(mutant.name)
            assert client.read("cnc_tick_counter_r") is not None  # it answers
        assert stored(client) == store_before, "an NC program changed the program store"
    elapsed_s = time.monotonic() - started
    assert_well(service, before.tick, before)
    summary = ", ".join(f"{k} {v}" for k, v in sorted(outcomes.items()))
    print(f"\nNC fuzz (seed {used_seed}): {run_scale.nc_mutations} mutants ({endless} with an "
          f"endless loop, {writes} writing files) in {elapsed_s:.1f} s: {summary}")
    figures.record("NC mutants checked and run (seed)",
                   f"{run_scale.nc_mutations} ({used_seed}), {endless} with endless loops, "
                   f"{writes} writing files (the store unchanged)", NODE)
    figures.record("NC outcomes", summary, NODE)


CLI_CHECK_EXITS = {0, 1, 2}  # clean, errors or aborted, no result (--wait-timeout)
CLI_RUN_EXITS = {0, 4, 5}  # finished, channel ERROR, --wait-timeout passed


CNC = Path(sys.executable).with_name("cnc")  # the console script of this environment


def cnc(service: ServiceProcess, *args: str) -> subprocess.CompletedProcess[str]:
    """The ``cnc`` CLI against ``service``, as a user runs it."""
    return subprocess.run(
        [str(CNC), "--endpoint", service.endpoint, "--timeout", str(CLIENT_TIMEOUT_S), *args],
        capture_output=True, text=True, timeout=120,
    )


def test_mutants_through_the_cli(service: ServiceProcess, run_scale: Scale, tmp_path) -> None:
    rnd = random.Random(seed() + 1)
    before = vitals(service.endpoint)
    codes: Counter[str] = Counter()
    # An endless loop first, so that the timeouts of both commands are exercised.
    chosen = [m for m in mutants(200, rnd) if m.endless][:1]
    chosen += mutants(run_scale.nc_cli_programs - len(chosen), rnd)
    for mutant in chosen:
        path = tmp_path / mutant.name
        path.write_bytes(mutant.data)
        checked = cnc(service, "check", str(path), "--wait-timeout", str(CHECK_TIMEOUT_S))
        assert checked.returncode in CLI_CHECK_EXITS, (mutant, checked.stdout, checked.stderr)
        # a check ended by an error (software limit) leaves the channel in ERROR, as a run
        # does: RESET before the run
        reset = cnc(service, "reset", "--standard")
        assert reset.returncode == 0, reset.stderr
        ran = cnc(service, "run", mutant.name, "--wait", "--wait-timeout", str(RUN_TIMEOUT_S))
        assert ran.returncode in CLI_RUN_EXITS, (mutant, ran.stdout, ran.stderr)
        for result in (checked, ran):
            assert "Traceback" not in result.stderr, result.stderr
            assert result.stdout or result.stderr, "the CLI said nothing"
        reset = cnc(service, "reset", "--standard")
        assert reset.returncode == 0, reset.stderr
        codes[f"check {checked.returncode}"] += 1
        codes[f"run {ran.returncode}"] += 1
    assert_well(service, before.tick, before)
    summary = ", ".join(f"exit {k} x{v}" for k, v in sorted(codes.items()))
    print(f"\nCLI: {len(chosen)} mutants: {summary}")
    figures.record("NC mutants through cnc check / cnc run --wait", f"{len(chosen)}: {summary}",
                   NODE)


STALL_BOUND_S = 5.0  # a command must be acknowledged, the check end, within this
SYNCHK_MACHINE_LOCK = 0x48  # execution mode of a syntax check
FAULTY_LINES = {
    "1000 errors": "N1 " * 1000,  # every N after the first is an error (3 kB)
    "1 error after 64000 blanks": "N1" + " " * 64_000 + "N1",
}


@pytest.mark.parametrize("line", FAULTY_LINES.values(), ids=FAULTY_LINES.keys())
def test_a_faulty_line_does_not_stall_the_cycle(line: str) -> None:
    own = start_service()
    stalled = True
    try:
        with Client(own.endpoint, timeout_s=STALL_BOUND_S) as client:
            client.upload("faulty.nc", (line + "\nG1 X1 F600\nM30\n").encode())
            client.write("ch1.mc_command_execution_mode_w", SYNCHK_MACHINE_LOCK)
            client.write("ch1.syn_chk.interactive", False)
            before = vitals(own.endpoint)
            client.run_program("faulty.nc")  # START must be acknowledged at once
            client.wait_program(timeout_s=STALL_BOUND_S)
            wait_for_tick_after(own.endpoint, before.tick, STALL_BOUND_S)
            stalled = False
    finally:
        if stalled and own.process.poll() is None:
            own.process.kill()  # its cycle thread waits for the check: SIGINT would hang
        code = own.stop()
    assert code == 0, own.log_text


ODD_ERROR_TEXTS = {
    "NUL": "G1 X1 F600 \x00\nM30\n",  # unknown word '\x00'
    "not-CP1252": "G1 X1 F600 \u0fc2\nM30\n",  # unknown word '\u0fc2'
    "over 255 characters": "L " + "y" * 300 + ".nc\nM30\n",  # program ... not found
}


@pytest.mark.parametrize("program", ODD_ERROR_TEXTS.values(),
                         ids=ODD_ERROR_TEXTS.keys())
def test_every_error_text_is_readable(service: ServiceProcess, program: str) -> None:
    with Client(service.endpoint, timeout_s=CLIENT_TIMEOUT_S) as client:
        client.upload("odd.nc", program.encode())
        try:
            with pytest.raises(ChannelError) as error:
                client.run_program("odd.nc")
                client.wait_program(timeout_s=RUN_TIMEOUT_S)
            assert "odd.nc:1:" in str(error.value)
            text = client.read("ch1.mc_error_1_text_r")  # cut to 255 bytes, "?" for NUL
            assert text and "\x00" not in text and len(text) <= 255
            client.reset()
            ran = cnc(service, "run", "odd.nc", "--wait")  # a channel in ERROR: exit 4
            assert ran.returncode == 4 and "odd.nc:1:" in ran.stderr, (ran.stdout, ran.stderr)
        finally:
            client.reset()
            client.delete_program("odd.nc")


def test_a_huge_g_number_is_an_nc_error(service: ServiceProcess) -> None:
    with Client(service.endpoint, timeout_s=CLIENT_TIMEOUT_S) as client:
        client.upload("huge-g.nc", b"G" + b"9" * 400 + b" X1 F600\nM30\n")
        faults_before = len(fault_records(service))
        try:
            with pytest.raises(ChannelError) as error:
                client.run_program("huge-g.nc")
                client.wait_program(timeout_s=RUN_TIMEOUT_S)
            assert "huge-g.nc:1:" in str(error.value)
            assert "fault" not in str(error.value), error.value
            assert len(fault_records(service)) == faults_before
        finally:
            client.reset()
            client.delete_program("huge-g.nc")
