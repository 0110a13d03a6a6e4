"""The smaller frictions of issue 29's walk-through, each against the real service where
it has one: ``cnc plot`` leaves the execution mode as it found it, a warning about a block
counts its column from 1, an operator refused an upload learns who may and how to do
without, ``make run`` takes the ADS address and the data directory, the ``ads`` extra and
the install line of docs/testing.md."""

from __future__ import annotations

import re
import subprocess
import tomllib
from pathlib import Path

import pytest

from cnc_objects.clients import Client
from cnc_objects.testing import serving
from tests.support.cli import cnc, json_lines
from tests.support.path_plot import PROGRAM
from tests.support.service import ROOT, RunningService

ADD_MDI_BLOCK = 0x80  # an execution mode bit that changes nothing of a program's path
PROD_TIME = 0x10


def test_plot_puts_back_the_execution_mode_in_effect(service: RunningService,
                                                      tmp_path: Path) -> None:
    with Client(service.endpoint) as c:  # a run in ADD_MDI_BLOCK: the mode in effect
        c.upload("part.nc", PROGRAM)
        c.write("ch1.mc_command_execution_mode_w", ADD_MDI_BLOCK)
        c.run_program("part.nc")
        c.wait_program(timeout_s=60)
        assert c.read("ch1.mc_active_execution_mode_r") == ADD_MDI_BLOCK
    source = tmp_path / "part.nc"
    source.write_bytes(PROGRAM)
    plotted = cnc("plot", str(source), "-o", str(tmp_path / "part.png"),
                  endpoint=service.endpoint)
    assert plotted.returncode == 0, plotted.stderr
    status = cnc("--json", "status", endpoint=service.endpoint)
    [record] = json_lines(status)
    assert record["execution_mode"] == "ADD_MDI_BLOCK"  # not PROD_TIME
    assert record["commanded_execution_mode"] == "ADD_MDI_BLOCK"
    with Client(service.endpoint) as c:
        assert c.read("ch1.mc_active_execution_mode_r") == ADD_MDI_BLOCK
        assert c.read("ch1.prod_time_trace") is False


def test_plot_from_standard_leaves_standard(service: RunningService, tmp_path: Path) -> None:
    source = tmp_path / "part.nc"
    source.write_bytes(PROGRAM)
    assert cnc("plot", str(source), "-o", str(tmp_path / "p.png"),
               endpoint=service.endpoint).returncode == 0
    shown = cnc("status", endpoint=service.endpoint).stdout
    assert "execution mode standard\n" in shown, shown
    assert "PROD_TIME" not in shown


def test_a_plot_that_fails_puts_the_mode_back_too(service: RunningService,
                                                   tmp_path: Path) -> None:
    source = tmp_path / "bad.nc"
    source.write_bytes(b"G01 X10 F600\nG01 X20 Q\nM30\n")
    assert cnc("plot", str(source), "-o", str(tmp_path / "bad.png"),
               endpoint=service.endpoint).returncode == 4
    with Client(service.endpoint) as c:
        assert c.read("ch1.mc_active_execution_mode_r") & PROD_TIME == 0


@pytest.mark.cnc_service(config="../e2e/data/low-buffer-machine.toml")
def test_the_buffer_warning_counts_columns_from_1(service: RunningService) -> None:
    """docs/examples/chords.nc with a 30-block buffer: warning 50301 at the block the path
    is in, ``chords.nc:LINE:1`` (it said ``:0``)."""
    ran = cnc("run", str(ROOT / "docs" / "examples" / "chords.nc"), "--wait",
              "--wait-timeout", "120", endpoint=service.endpoint)
    assert ran.returncode == 0, ran.stderr
    warning = next(line for line in ran.stderr.splitlines() if "50301" in line)
    assert re.match(r"warning 50301: chords\.nc:\d+:1: the look-ahead buffer of 30 blocks",
                    warning), warning


def test_the_stopped_check_warning_counts_columns_from_1(service: RunningService,
                                                         tmp_path: Path) -> None:
    program = tmp_path / "errors.nc"
    program.write_text("".join(f"G01 X{k} Q\n" for k in range(1, 8)) + "M30\n")
    checked = cnc("--json", "check", str(program), "--errors-total", "2", "--log",
                  endpoint=service.endpoint)
    assert checked.returncode == 1, checked.stderr
    with Client(service.endpoint) as c:
        lines = c.channel_errors(1)
    stopped = [line for line in lines if "syntax check stopped after" in line]
    assert stopped and re.search(r"errors\.nc:\d+:1: ", stopped[0]), lines
    assert not any(re.search(r"\.nc:\d+:0: ", line) for line in lines), lines


def test_an_operator_refused_an_upload_learns_who_may(tmp_path: Path) -> None:
    keys = tmp_path / "keys"
    for args in (("server", "--dir", str(keys)),
                 ("alice", "--dir", str(tmp_path / "alice"), "--role", "operator",
                  "--allow-in", str(keys))):
        assert cnc("keys", "new", *args).returncode == 0
    program = tmp_path / "part.nc"
    program.write_bytes(PROGRAM)
    alice = ("--key", str(tmp_path / "alice" / "alice.key_secret"),
             "--server-key", str(keys / "server.key"))
    with serving("--keys", str(keys)) as service:
        upload = cnc(*alice, "upload", str(program), endpoint=service.endpoint)
        assert upload.returncode == 1
        assert upload.stderr.strip() == (
            "error: ADS 0x704 INVALIDACCESS: role operator may not change the program "
            "store (upload, delete); admin may")
        run = cnc(*alice, "run", str(program), endpoint=service.endpoint)
        assert run.returncode == 1
        assert "role operator may not change the program store (upload, delete); admin may" \
            in run.stderr
        assert "a program in the store runs by its name" in run.stderr
        assert "cnc programs" in run.stderr


def test_make_run_takes_the_ads_address_and_the_data_directory() -> None:
    shown = subprocess.run(
        ["make", "-n", "-W", "pyproject.toml", "run", "ADS=127.0.0.1:48899",
         "DATA_DIR=/srv/cnc"], cwd=ROOT, capture_output=True, text=True, timeout=60)
    if shown.returncode != 0 and "No such file" in shown.stderr:
        pytest.skip("make is not installed")
    assert shown.returncode == 0, shown.stderr
    service_line = " ".join(line.strip(" \\") for line in shown.stdout.splitlines()
                            if "cnc-service" in line or line.startswith("\t--"))
    assert "--ads 127.0.0.1:48899" in shown.stdout and "--data-dir /srv/cnc" in shown.stdout
    plain = subprocess.run(["make", "-n", "-W", "pyproject.toml", "run"], cwd=ROOT,
                           capture_output=True, text=True, timeout=60)
    assert "--ads" not in plain.stdout and "--data-dir" not in plain.stdout
    assert "cnc-service --endpoint tcp://127.0.0.1:5555" in service_line
    readme = (ROOT / "README.md").read_text()
    assert "ADS=" in readme and "DATA_DIR=" in readme


def test_pyads_is_the_ads_extra_and_docs_name_it() -> None:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert [r for r in project["optional-dependencies"]["ads"] if r.startswith("pyads")]
    ads_doc = (ROOT / "docs" / "ads.md").read_text()
    assert "pip install -e '.[ads]'" in ads_doc and "cnc-objects[ads]" in ads_doc


def test_testing_doc_installs_from_the_clone() -> None:
    install = (ROOT / "docs" / "testing.md").read_text().split("## Install", 1)[1]
    install = install.split("\n## ", 1)[0]
    assert "pip install cnc-objects " not in install  # not on PyPI
    assert "pip install -e /path/to/cnc-objects" in install
    assert "pip wheel" in install
