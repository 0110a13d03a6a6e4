"""``cnc-hmi`` driven by textual's headless Pilot against a real service (virtual clock).

Every assertion waits for a condition (``wait_until``), never for a fixed time: values
reach the widgets by subscription, commands by the keys a user presses.
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time

import pytest
from textual.widgets import OptionList

from cnc_objects.clients.client import AsyncClient
from cnc_objects.clients.hmi import text
from cnc_objects.clients.hmi.app import HmiApp
from cnc_objects.clients.hmi.program_picker import ProgramPicker
from tests.support.hmi import LONG_PROGRAM, SIZE, WAIT_S, filled, shown, started, wait_until
from tests.support.service import RunningService, start_service


@pytest.fixture
def free_endpoint() -> str:
    """An endpoint where nothing listens (a port the OS just handed out and took back)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    return f"tcp://127.0.0.1:{port}"










async def test_shows_channels_and_axes_from_the_service(endpoint: str) -> None:
    async with HmiApp(endpoint).run_test(size=SIZE) as pilot, AsyncClient(endpoint) as c:
        app = await started(pilot)
        assert [ch.key for ch in app.machine.channels] == ["ch1", "ch2"]
        assert [a.name for a in app.machine.channels[1].axes] == ["X", "Y", "Z"]
        for ch in app.machine.channels:
            v = await c.read_many([ch.obj("mc_active_mode_r"), ch.obj("mc_active_state_r"),
                                   ch.obj("mc_active_feed_override_r"), ch.suspend("state_r")])
            assert app.channels.cell(ch, "mode") == text.mode(v[ch.obj("mc_active_mode_r")])
            assert app.channels.cell(ch, "state") == text.state(v[ch.obj("mc_active_state_r")])
            assert app.channels.cell(ch, "override") == text.percent(
                v[ch.obj("mc_active_feed_override_r")])
            assert app.channels.cell(ch, "output") == (
                "suspended" if v[ch.suspend("state_r")] else "active")
            assert (app.channels.cell(ch, "spindle"), app.channels.cell(ch, "rpm")) == ("M5", "0")
        # The default machine: channel 1 holds the drives, channel 2 (jog of path) waits.
        assert app.axes.cell("ch1.ax1", "axis") == "ch1.X"
        assert app.axes.cell("ch1.ax1", "link") == "0 linked → ax1"
        assert app.axes.cell("ch2.ax3", "link") == "1 requested"
        actual = await c.read("ax2.actual_position_acs")
        assert app.axes.cell("ch1.ax2", "actual") == app.axes.cell("ch2.ax2", "actual") == text.mm(
            actual)
        # The key bindings are in the footer.
        shown = {(k.key_display or k.key) for k in app.query("FooterKey")}
        assert {"c", "p", "s", "h", "r", "b", "+", "-", "j", "l", "m", "q"} <= shown


async def test_program_keys_select_start_hold_resume_reset(service: RunningService) -> None:
    ep = service.endpoint
    async with AsyncClient(ep) as c, HmiApp(ep).run_test(size=SIZE) as pilot:
        await c.upload("long.nc", LONG_PROGRAM)
        app = await started(pilot)
        state = "ch1.mc_active_state_r"

        await pilot.press("p")  # the dialog lists the store; typing narrows it, enter selects
        await wait_until(pilot, lambda: isinstance(app.screen, ProgramPicker), what="dialog")
        await pilot.press("l", "o", "n", "g", "enter")
        await wait_until(pilot, lambda: app.channels.cell("ch1", "program") == "long.nc")
        assert app.message.text == "ch1: selected long.nc" and not app.message.is_error
        assert await c.read("ch1.mc_active_program_name_r") == "long.nc"

        await pilot.press("s")
        await wait_until(pilot, lambda: app.axes.cell("ch1.ax1", "command") != "0.0000",
                         what="X moves")
        await wait_until(pilot, lambda: app.axes.cell("ch1.ax1", "actual") != "0.0000")
        assert app.channels.cell("ch1", "state") in ("ACTIVE", "HOLD")  # not ended: 13 h
        assert app.channels.cell("ch1", "block").startswith("N")

        await pilot.press("h")
        await wait_until(pilot, lambda: app.channels.cell("ch1", "state") == "HOLD",
                         what=shown(app))
        assert text.state(await c.read(state)) == "HOLD"
        await pilot.press("s")  # resume
        await wait_until(pilot, lambda: app.channels.cell("ch1", "state") == "ACTIVE",
                         what=shown(app))
        await pilot.press("r")
        await wait_until(pilot, lambda: app.channels.cell("ch1", "state") not in ("ACTIVE", "HOLD"),
                         what=shown(app))
        assert app.channels.cell("ch1", "state") == text.state(await c.read(state))
        assert app.message.text == "ch1: RESET"


async def test_program_dialog_lists_the_nc_programs_only(service: RunningService) -> None:
    """The store also holds what the kernel writes there (a run's error log and #MSG SAVE
    file, a syntax check's dec01.sc, a PROD_TIME trace) and user cycles: not programs."""
    ep = service.endpoint
    async with AsyncClient(ep) as c, HmiApp(ep).run_test(size=SIZE) as pilot:
        await c.upload("Part.NC", b"G1 X1 F600\nM30\n")
        await c.upload("SUB", b"G1 X2 F600\nM17\n")
        await c.upload("drill.ecy", b"G1 X3 F600\nM17\n")
        await c.upload("bad.nc", b'#MSG SAVE ["tool %d", 3]\nG1 X1 F600\nG1 Y2 Q7\nM30\n')
        await c.syntax_check("Part.NC")
        await c.trace_run("Part.NC")
        await c.run_program("bad.nc")
        app = await started(pilot)
        await wait_until(pilot, lambda: app.channels.cell("ch1", "state") == "ERROR")
        stored = [p.name for p in await c.programs()]
        assert stored == ["Part.NC", "SUB", "bad.nc", "drill.ecy"]
        # the kernel's files are in the output area, never among the programs
        assert [p.name for p in await c.outputs()] == [
            "dec01.sc", "errors-ch1.log", "msg_save.txt", "prodtime01.csv"]

        await pilot.press("p")
        await wait_until(pilot, lambda: isinstance(app.screen, ProgramPicker), what="dialog")
        options = app.screen.query_one(OptionList)

        def listed() -> list[str]:
            return [str(options.get_option_at_index(k).prompt)
                    for k in range(options.option_count)]

        assert listed() == ["Part.NC", "SUB", "bad.nc"]
        await pilot.press("s")  # typing narrows the NC programs only (not drill.ecy)
        await wait_until(pilot, lambda: listed() == ["SUB"], what="filtered to SUB")
        await pilot.press("escape")
        await wait_until(pilot, lambda: app.message.text == "ch1: no program selected")


async def test_override_and_single_block_keys(service: RunningService) -> None:
    ep = service.endpoint
    async with AsyncClient(ep) as c, HmiApp(ep).run_test(size=SIZE) as pilot:
        app = await started(pilot)
        override = "ch1.mc_active_feed_override_r"
        assert await c.read(override) == 1000
        await pilot.press("minus", "minus")
        await wait_until(pilot, lambda: app.channels.cell("ch1", "override") == "80.0 %")
        assert await c.read(override) == 800
        await pilot.press("plus")
        await wait_until(pilot, lambda: app.channels.cell("ch1", "override") == "90.0 %")
        assert await c.read(override) == 900
        await pilot.press("plus", "plus")  # held at 100 %
        await wait_until(pilot, lambda: app.message.text == "ch1: feed override 100.0 %")
        await wait_until(pilot, lambda: app.channels.cell("ch1", "override") == "100.0 %")

        await pilot.press("b")
        await wait_until(pilot, lambda: app.channels.cell("ch1", "single") == "on")
        assert await c.read("ch1.mc_active_single_block_r") is True
        await pilot.press("b")
        await wait_until(pilot, lambda: app.channels.cell("ch1", "single") == "off")
        assert await c.read("ch1.mc_active_single_block_r") is False


async def test_jog_of_path_key_hands_the_axes_over(service: RunningService) -> None:
    ep = service.endpoint
    suspended = "gpCh[{}].bahn_mc_control.suspend_axis_output.state_r"
    async with AsyncClient(ep) as c, HmiApp(ep).run_test(size=SIZE) as pilot:
        app = await started(pilot)
        await pilot.press("j")  # channel 1 gives its drives up
        await wait_until(pilot, lambda: app.channels.cell("ch1", "output") == "suspended")
        assert await c.read(suspended.format(0)) is True
        assert app.message.text == "ch1: axis output suspended (jog of path)"
        await wait_until(pilot, lambda: app.axes.cell("ch1.ax1", "link") == "1 requested")

        await pilot.press("c", "j")  # channel 2 takes them
        await wait_until(pilot, lambda: app.channels.cell("ch2", "output") == "active")
        assert await c.read(suspended.format(1)) is False
        await wait_until(pilot, lambda: app.axes.cell("ch2.ax1", "link") == "0 linked → ax1")
        assert await c.read("ch2.ax1.link_state") == 0

        await pilot.press("j", "c", "j")  # and back to channel 1
        await wait_until(pilot, lambda: app.axes.cell("ch1.ax1", "link") == "0 linked → ax1")
        assert app.channels.cell("ch2", "output") == "suspended"


async def test_lookahead_shows_the_elements_of_a_held_program(service: RunningService) -> None:
    ep = service.endpoint
    async with AsyncClient(ep) as c, HmiApp(ep).run_test(size=SIZE) as pilot:
        await c.upload("long.nc", LONG_PROGRAM)
        app = await started(pilot)
        await c.run_program("long.nc")
        await wait_until(pilot, lambda: app.channels.cell("ch1", "state") == "ACTIVE")
        await pilot.press("h", "l")
        await wait_until(pilot, lambda: app.channels.cell("ch1", "state") == "HOLD")
        table = app.lookahead.table

        def numbers() -> list[str]:
            return [str(table.get_row_at(k)[1]) for k in range(table.row_count)]

        # Mode 2: the elements ahead of the held tool, blocks of the program.
        await wait_until(pilot, lambda: table.row_count > 3, what="elements ahead")
        assert set(numbers()) <= {str(10 * k) for k in range(1, 21)}
        assert "200" in numbers()  # the last block is prepared long before it runs
        assert "mode 2" in app.lookahead.border_title

        await pilot.press("m")  # mode 1: the marked area from its LOG ON entry
        await wait_until(pilot, lambda: "mode 1" in app.lookahead.border_title
                         and table.row_count > 0)
        assert str(table.get_row_at(0)[0]) == "LOG ON" and str(table.get_row_at(0)[4]) == "7"
        assert numbers()[1:3] == ["10", "20"]

        await pilot.press("c")  # channel 2 has no FCT_CONTOUR_LAH: the panel says why
        await wait_until(pilot, lambda: "0x701" in str(app.lookahead.summary.render()))
        await pilot.press("l")
        assert not app.lookahead.display


async def test_refused_command_shows_the_ads_code(service: RunningService) -> None:
    async with HmiApp(service.endpoint).run_test(size=SIZE) as pilot:
        app = await started(pilot)
        await pilot.press("s")  # nothing selected: the channel refuses START
        await wait_until(pilot, lambda: app.message.is_error)
        assert app.message.text.startswith("START refused: ADS 0x707 NOTREADY: channel 1 is ")
        await pilot.press("p")
        await wait_until(pilot, lambda: isinstance(app.screen, ProgramPicker))
        await pilot.press("n", "o", "p", "e", "enter")
        await wait_until(pilot, lambda: "0x70c" in app.message.text)
        assert app.message.text.startswith("select program refused: ADS 0x70c NOTFOUND")
        assert app.is_running


async def test_channel_errors_are_listed(service: RunningService) -> None:
    ep = service.endpoint
    async with AsyncClient(ep) as c, HmiApp(ep).run_test(size=SIZE) as pilot:
        await c.upload("bad.nc", b"G1 X1 F600\nG1 Y2 Q7\nM30\n")
        app = await started(pilot)
        await c.run_program("bad.nc")
        await wait_until(pilot, lambda: app.channels.cell("ch1", "state") == "ERROR")
        await wait_until(pilot, lambda: app.channels.cell("ch1", "errors") == "1")
        await wait_until(pilot, lambda: "Q7" in str(app.errors.render()))
        assert app.errors.errors["ch1"] == await c.channel_errors(1)
        assert app.errors.errors["ch1"][0].startswith("error 21220: bad.nc:2:7: ")
        await pilot.press("j")  # no suspension in ERROR: the service refuses, the HMI says so
        await wait_until(pilot, lambda: app.message.is_error)
        assert app.message.text.startswith("suspend axis output refused: ADS 0x707 NOTREADY")
        await pilot.press("r")
        await wait_until(pilot, lambda: app.channels.cell("ch1", "errors") == "0")
        await wait_until(pilot, lambda: str(app.errors.render()) == "no errors")


async def test_unreachable_service_shows_a_clear_message(free_endpoint: str) -> None:
    async with HmiApp(free_endpoint, timeout_s=0.3).run_test(size=SIZE) as pilot:
        app = pilot.app
        line = f"service at {free_endpoint} not reachable — retrying"
        await wait_until(pilot, lambda: app.message.text == line)
        assert app.message.is_error and app.client is None
        await pilot.press("s")  # a key without a service: a message, no crash
        await wait_until(pilot, lambda: app.message.text == f"START: {line}")
        assert app.is_running


async def test_reconnects_when_the_service_comes_back(free_endpoint: str) -> None:
    first = start_service("--endpoint", free_endpoint)
    try:
        async with HmiApp(free_endpoint, timeout_s=0.3).run_test(size=SIZE) as pilot:
            app = await started(pilot)
            assert first.stop() == 0
            await wait_until(pilot, lambda: "not reachable" in app.message.text)
            assert "stale" in app.channels.classes
            second = start_service("--endpoint", free_endpoint)
            try:
                await wait_until(pilot, lambda: app.message.text.startswith("connected"))
                await wait_until(pilot, lambda: filled(app))
                await pilot.press("minus")  # the new session's subscriptions work
                await wait_until(pilot, lambda: app.channels.cell("ch1", "override") == "90.0 %")
            finally:
                assert second.stop() == 0
    finally:
        first.stop()


def _cli(module: str, *args: str) -> subprocess.CompletedProcess:
    """``python -m <module> *args`` to its end; a wide terminal keeps rich's error box
    on one line per message."""
    return subprocess.run([sys.executable, "-m", module, *args], capture_output=True,
                          text=True, timeout=30, env={**os.environ, "COLUMNS": "200"})


def test_cnc_hmi_options_in_the_style_of_cnc() -> None:
    """Help with defaults and the environment variable; bad usage exits 2 naming the
    option (the HMI itself never starts: it needs a terminal)."""
    shown = _cli("cnc_objects.clients.hmi.app", "--help")
    assert shown.returncode == 0
    assert "Usage: cnc-hmi [OPTIONS]" in shown.stdout
    assert "[env var: CNC_ENDPOINT]" in shown.stdout
    assert "[default: tcp://127.0.0.1:5555]" in shown.stdout and "[default: 2.0]" in shown.stdout
    for args, message in [(["--timeout", "soon"], "Invalid value for '--timeout'"),
                          (["--timeout", "0"], "Invalid value for '--timeout'"),
                          (["--endpoint"], "Option '--endpoint' requires an argument"),
                          (["--endpont", "x"], "No such option: --endpont")]:
        result = _cli("cnc_objects.clients.hmi.app", *args)
        assert result.returncode == 2, args
        assert message in result.stderr and "Traceback" not in result.stderr


def test_latency_options_in_the_style_of_cnc() -> None:
    module = "cnc_objects.clients.hmi.latency"
    shown = _cli(module, "--help")
    assert shown.returncode == 0
    assert f"Usage: python -m {module} [OPTIONS]" in shown.stdout
    assert "--moving" in shown.stdout and "[default: 50]" in shown.stdout
    for args, message in [(["--count", "0"], "Invalid value for '--count'"),
                          (["--count", "many"], "Invalid value for '--count'")]:
        result = _cli(module, *args)
        assert result.returncode == 2, args
        assert message in result.stderr and "Traceback" not in result.stderr


async def test_jog_keys_move_the_chosen_axis_in_manual_mode(endpoint: str) -> None:
    """``]``/``[`` jog one increment in MANUAL (selected by the key); ``a`` and ``i``
    choose axis and increment (docs/hmi.md, docs/manual.md)."""
    async with HmiApp(endpoint).run_test(size=SIZE) as pilot, AsyncClient(endpoint) as c:
        app = await started(pilot)
        await c.reset(1)
        y0 = await c.read("ch1.ax2.command_position_acs")
        await pilot.press("a")  # Y
        assert app.message.text == "ch1: jog axis Y"
        await pilot.press("i", "i", "i")  # 1 mm -> 10 mm -> continuous -> 1 um
        assert app.message.text == "jog increment 0.001 mm"
        assert app.mode_bar.jog_line.render().plain.startswith("jog ch1.Y 0.001 mm")
        await pilot.press("right_square_bracket")
        await wait_until(pilot, lambda: app.message.text == "ch1: jog Y+0.001 mm",
                         what=lambda: app.message.text)

        async def position() -> int:
            return await c.read("ch1.ax2.command_position_acs")

        deadline = time.monotonic() + WAIT_S
        while await position() != y0 + 10:
            assert time.monotonic() < deadline, "Y did not move one increment"
            await pilot.pause()
        assert await c.read("ch1.mc_active_mode_r") == 4  # MANUAL
        await pilot.press("left_square_bracket", "left_square_bracket")
        deadline = time.monotonic() + WAIT_S
        while await position() != y0 - 10:
            assert time.monotonic() < deadline, "Y did not move back two increments"
            await pilot.pause()
        shown = {(k.key_display or k.key) for k in app.query("FooterKey")}
        assert {"]", "[", "a", "i"} <= shown
        await c.reset(1)


async def test_positions_speed_and_override_in_engineering_units(service: RunningService) -> None:
    """mm, mm/min and % by the service's scale of each object (not the HMI's own factors):
    a 0.1 um position is 4 decimals of a mm, F1 (16.67 um/s) is 1 mm/min."""
    ep = service.endpoint
    async with AsyncClient(ep) as c, HmiApp(ep).run_test(size=SIZE) as pilot:
        app = await started(pilot)
        await c.write("ch1.mc_command_feed_override_w", 755)  # 0.1 %
        await wait_until(pilot, lambda: app.channels.cell("ch1", "override") == "75.5 %")
        await c.write("ch1.mc_command_feed_override_w", 1000)
        before = await c.mdi("G01 X12.3456 Y-0.189 F6000")
        await c.wait_mdi(before, timeout_s=WAIT_S)
        await wait_until(pilot, lambda: app.axes.cell("ch1.ax1", "command") == "12.3456")
        await wait_until(pilot, lambda: app.axes.cell("ch1.ax2", "actual") == "-0.1890")
        await wait_until(pilot, lambda: app.channels.cell("ch1", "feed") == "0")  # stands
        await c.upload("long.nc", LONG_PROGRAM)
        await c.run_program("long.nc")
        await wait_until(pilot, lambda: app.channels.cell("ch1", "feed") == "1",
                         what=lambda: f"feed cell {app.channels.cell('ch1', 'feed')!r}")
        await c.reset()
