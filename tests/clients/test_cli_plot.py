"""``cnc plot`` and ``Client.trace_run``: a traced PROD_TIME dry run on the real service."""

from __future__ import annotations

import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from cnc_objects.clients import AdsError, Client
from cnc_objects.protocol.wait_reasons import WaitReason
from tests.support.cli import cnc, json_lines
from tests.support.path_plot import FEED_RGB, PROGRAM, TOP_SPEED_RGB, png_pixels
from tests.support.service import RunningService

# PROGRAM: a line, a half circle (G2, r 10) and a line at a lower feed: 20 + 10*pi + 20 mm
LENGTH_MM = 40.0 + 10.0 * math.pi


def test_trace_run_follows_the_program_and_moves_nothing(service: RunningService) -> None:
    with Client(service.endpoint) as c:
        c.upload("part.nc", PROGRAM)
        c.write("ch1.mc_command_execution_mode_w", 0x80)  # ADD_MDI_BLOCK: must come back
        axes = ["ax1.actual_position_acs", "ax2.actual_position_acs", "ch1.ax1.command_position_acs"]
        before = c.read_many(axes)
        trace = c.trace_run("part.nc")
        after = c.read_many(axes)
        program_time_s = c.read("ch1.program_time")
        restored = c.read_many(["ch1.mc_command_execution_mode_r", "ch1.prod_time_trace"])
        state = c.read("ch1.mc_active_state_r")
    assert after == before  # no axis of the live machine moved
    assert restored == {"ch1.mc_command_execution_mode_r": 0x80, "ch1.prod_time_trace": False}
    assert state == 3  # READY
    assert trace.ended == "READY" and trace.program == "part.nc" and trace.stride == 1
    assert trace.program_time_s == pytest.approx(program_time_s, abs=1e-9)
    assert (trace.axis("X")[-1], trace.axis("Y")[-1]) == (0.0, 20.0)  # the end point
    assert trace.path_mm[-1] == pytest.approx(LENGTH_MM, abs=1e-6)
    # every cycle of 1 ms, in order, along a path that only grows
    assert np.allclose(np.diff(trace.t_s), 0.001)
    assert np.all(np.diff(trace.path_mm) >= -1e-12)
    # the speed stays within the feed limit and reaches F6000 (100 mm/s) on the 20 mm line
    moving = trace.feed_limit_mm_s > 0.0
    assert np.all(trace.v_mm_s[moving] <= trace.feed_limit_mm_s[moving] + 1e-9)
    assert trace.v_mm_s.max() == pytest.approx(100.0)
    assert set(trace.feed_limit_mm_s[moving]) >= {100.0, 50.0}
    # on the half circle every sample is 10 mm from its centre (20, 10)
    on_arc = (trace.path_mm > 20.0 + 1e-6) & (trace.path_mm < 20.0 + 10.0 * math.pi - 1e-6)
    radius = np.hypot(trace.axis("X")[on_arc] - 20.0, trace.axis("Y")[on_arc] - 10.0)
    assert on_arc.sum() > 100 and np.allclose(radius, 10.0, atol=1e-9)


def test_trace_time_is_the_time_of_a_real_run(service: RunningService) -> None:
    with Client(service.endpoint) as c:
        c.upload("part.nc", PROGRAM)
        traced = c.trace_run("part.nc").program_time_s
        c.run_program("part.nc")
        c.wait_program(timeout_s=30)
        real = c.read("ch1.program_time")
        end = c.read_many(["ch1.ax1.command_position_acs", "ch1.ax2.command_position_acs"])
    assert traced == pytest.approx(real, abs=1e-9)
    assert end == {"ch1.ax1.command_position_acs": 0, "ch1.ax2.command_position_acs": 200_000}


def test_a_long_run_is_thinned_to_fit_one_download(service: RunningService) -> None:
    with Client(service.endpoint) as c:
        c.upload("slow.nc", b"G01 X150 F60\nM30\n")  # 150 s: 150,000 cycles
        trace = c.trace_run("slow.nc")
        size = next(p.size_bytes for p in c.outputs() if p.name == "prodtime01.csv")
    assert trace.stride > 1 and len(trace.t_s) < 20_001
    assert size <= 1_000_000
    assert trace.axis("X")[-1] == 150.0 and trace.program_time_s == pytest.approx(150.001)


def test_trace_run_refuses_a_working_channel(service: RunningService) -> None:
    with Client(service.endpoint) as c:
        # M0 stops the run until START: it stays, however fast the event-speed clock is
        c.upload("slow.nc", b"G01 X1 F600\nM0\nG01 X150\nM30\n")
        c.run_program("slow.nc")
        deadline = time.monotonic() + 30
        while c.read("ch1.mc_wait_reason_r") != WaitReason.PROGRAMMED_STOP:
            assert time.monotonic() < deadline, "the run never reached its M0"
        with pytest.raises(AdsError, match="needs a channel that is not working") as caught:
            c.trace_run("slow.nc")
        assert caught.value.code == 0x707  # DEVICE_NOTREADY
        assert c.read("ch1.mc_active_state_r") == 4  # the real run goes on (at its M0)
        assert c.read("ch1.mc_active_program_name_r") == "slow.nc"


def test_cnc_plot_writes_the_png(endpoint: str, tmp_path: Path) -> None:
    source = tmp_path / "part.nc"
    source.write_bytes(PROGRAM)
    target = tmp_path / "out.png"
    result = cnc("--json", "plot", str(source), "-o", str(target), endpoint=endpoint)
    assert result.returncode == 0, result.stderr
    [record] = json_lines(result)
    assert record["output"] == str(target) and record["ended"] == "READY"
    assert record["path_mm"] == pytest.approx(LENGTH_MM, abs=0.5e-4)  # --json: 0.1 um
    assert record["v_max_mm_s"] == pytest.approx(100.0)
    img = png_pixels(target.read_bytes())
    assert img.shape == (800 + 600, 1200, 3)
    # the path at F6000 (the top of the speed colours) and the feed limit (red) are drawn
    assert np.any(np.all(img == TOP_SPEED_RGB, axis=2))
    assert np.any(np.all(img == FEED_RGB, axis=2))


def test_cnc_plot_default_output_and_human_line(endpoint: str, tmp_path: Path) -> None:
    source = tmp_path / "arc.nc"
    source.write_bytes(PROGRAM)
    result = cnc("plot", str(source), "--width", "600", "--axes", "XY", endpoint=endpoint,
                 cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "arc.png: arc.nc in channel 1" in result.stdout and "READY" in result.stdout
    assert png_pixels((tmp_path / "arc.png").read_bytes()).shape[1] == 600


def test_cnc_plot_of_a_failing_program_draws_up_to_the_error(
    service: RunningService, tmp_path: Path
) -> None:
    source = tmp_path / "bad.nc"
    source.write_bytes(b"G01 X10 F600\nG01 X20 Q\nM30\n")
    target = tmp_path / "bad.png"
    result = cnc("plot", str(source), "-o", str(target), endpoint=service.endpoint)
    assert result.returncode == 4, result.stderr
    assert "ended in ERROR" in result.stderr and "cnc reset" in result.stderr
    assert target.is_file()


@pytest.mark.parametrize("args, message", [
    (["--axes", "X"], "two axis letters"),
    (["--axes", "XQ"], "no axis 'Q'"),
])
def test_cnc_plot_usage_errors(endpoint: str, tmp_path: Path, args: list[str], message: str) -> None:
    source = tmp_path / "part.nc"
    source.write_bytes(PROGRAM)
    result = cnc("plot", str(source), "-o", str(tmp_path / "x.png"), *args, endpoint=endpoint)
    assert result.returncode == 2 and message in result.stderr


def test_cnc_plot_unknown_program_and_no_service(endpoint: str, tmp_path: Path) -> None:
    missing = cnc("plot", "no-such.nc", "-o", str(tmp_path / "x.png"), endpoint=endpoint)
    assert missing.returncode == 1 and "0x70c" in missing.stderr and "no-such.nc" in missing.stderr
    nobody = cnc("--timeout", "0.3", "plot", "x.nc", endpoint="tcp://127.0.0.1:9")
    assert nobody.returncode == 3


def test_cnc_starts_without_importing_matplotlib() -> None:
    code = ("import sys; import cnc_objects.clients.cli; "
            "print(sorted(m for m in sys.modules if m.split('.')[0] == 'matplotlib'))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            timeout=60)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[]"


def test_cnc_plot_without_matplotlib_names_the_extra(service: RunningService,
                                                     tmp_path: Path) -> None:
    source = tmp_path / "part.nc"
    source.write_bytes(PROGRAM)
    target = tmp_path / "out.png"
    # None in sys.modules makes every "import matplotlib" fail, as when it is not installed
    code = ("import sys; sys.modules['matplotlib'] = None; "
            "from cnc_objects.clients.cli import main; main()")
    result = subprocess.run(
        [sys.executable, "-c", code, "--endpoint", service.endpoint, "plot", str(source),
         "-o", str(target)], capture_output=True, text=True, timeout=60)
    assert result.returncode == 2
    assert result.stderr.splitlines() == [
        "error: plots need matplotlib, which is not installed: pip install "
        "'cnc-objects[plot]'"]
    assert not target.exists()
    with Client(service.endpoint) as c:  # refused before anything reached the service
        assert [p.name for p in c.programs()] == []
