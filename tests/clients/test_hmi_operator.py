"""``cnc-hmi`` as an operator uses it (issue 29): mode selection, MDI with history, the
program text following the block in execution, continuous jog, and a disconnected HMI
that greys its values and says since when. Headless Pilot against a real service
(virtual clock); every assertion waits for a condition, never for a fixed time."""

from __future__ import annotations

import re
import time
from pathlib import Path

import pytest
from textual.pilot import Pilot

from cnc_objects.clients.client import AsyncClient
from cnc_objects.clients.hmi import manual_keys, text
from cnc_objects.clients.hmi.app import HmiApp
from cnc_objects.clients.hmi.mdi import MdiHistory
from tests.support.broker import free_port
from tests.support.hmi import SIZE, WAIT_S, shown, started, wait_until
from tests.support.service import RunningService, start_service

NO_REPLY = re.compile(r"no reply from \S+ since (\d\d:\d\d:\d\d) \((\d+) s\)")

# 1 mm blocks at F1: a minute of kernel time each, a few seconds of wall time with the
# HMI's subscriptions (every 20 ms of kernel time) under the event-speed clock, so the
# marked line moves while the test watches and the channel still works when F4 is pressed
LONG_PROGRAM = "\n".join(
    ["N5 G90 G17"] + [f"N{10 * k} G1 X{k} Y{k % 2} F1" for k in range(1, 21)]
    + ["N310 M30", ""]).encode()


async def type_text(pilot: Pilot, line: str) -> None:
    """Type ``line`` key by key, as a person would."""
    await pilot.press(*("space" if ch == " " else ch for ch in line))


async def test_mode_keys_and_the_mode_bar_select_the_channel_mode(
        service: RunningService) -> None:
    ep = service.endpoint
    async with AsyncClient(ep) as c, HmiApp(ep).run_test(size=SIZE) as pilot:
        app = await started(pilot)
        mode = "ch1.mc_active_mode_r"
        await pilot.press("f4")
        await wait_until(pilot, lambda: app.mode_bar.shown_mode == "MANUAL",
                         what=lambda: app.message.text)
        assert await c.read(mode) == 4 and app.channels.cell("ch1", "mode") == "MANUAL"
        assert app.message.text == "ch1: mode MANUAL"

        await pilot.click("#mode-automatic")  # the visible control
        await wait_until(pilot, lambda: app.mode_bar.shown_mode == "AUTOMATIC")
        assert await c.read(mode) == 2

        await pilot.press("f3")  # MDI: the keys go to the MDI line
        await wait_until(pilot, lambda: app.mode_bar.shown_mode == "MDI")
        assert app.focused is app.mdi and await c.read(mode) == 3
        await pilot.press("escape")
        assert app.focused is app.channels

        await pilot.press("c", "f4")  # the bar shows the current channel's mode
        await wait_until(pilot, lambda: app.channels.cell("ch2", "mode") == "MANUAL")
        await wait_until(pilot, lambda: app.mode_bar.shown_mode == "MANUAL")
        assert await c.read("ch2.mc_active_mode_r") == 4
        await pilot.press("c")
        assert app.mode_bar.shown_mode == "MDI"


async def test_mdi_line_runs_blocks_and_recalls_its_history(
        service: RunningService, tmp_path: Path) -> None:
    ep = service.endpoint
    history = tmp_path / "state" / "mdi-history"
    first, second = "G1 X2 F6000 ; by hmi", "G1 X0.5 F6000"
    async with AsyncClient(ep) as c, HmiApp(ep, mdi_history=history).run_test(
            size=SIZE) as pilot:
        app = await started(pilot)
        await pilot.press("e")
        assert app.focused is app.mdi
        await type_text(pilot, first)  # b, h, i, m, y typed as text, not as commands
        await pilot.press("enter")
        await wait_until(pilot, lambda: app.axes.cell("ch1.ax1", "command") == "2.0000",
                         what=lambda: app.message.text)
        assert app.message.text == f"ch1: MDI {first}"
        assert app.channels.cell("ch1", "single") == "off" and app.is_running
        await wait_until(pilot, lambda: app.mode_bar.shown_mode == "MDI")
        await wait_until(pilot, lambda: "manual blocks (MDI)" in str(app.program_view.render()),
                         what=lambda: str(app.program_view.render()))
        await type_text(pilot, second)
        await pilot.press("enter")
        await wait_until(pilot, lambda: app.axes.cell("ch1.ax1", "command") == "0.5000",
                         what=lambda: app.message.text)
        assert await c.read("ch1.mc_manual_blocks_done_r") >= 2

        recalled = []
        for key in ("up", "up", "up", "down", "down"):
            await pilot.press(key)
            recalled.append(app.mdi.value)
        assert recalled == [second, first, first, second, ""]
        await type_text(pilot, "G1")  # a draft survives a look into the history
        await pilot.press("up", "down")
        assert app.mdi.value == "G1"

        await pilot.press("escape", "r")  # keys are commands again
        await wait_until(pilot, lambda: app.message.text == "ch1: RESET")

    # kept in the file: the next session recalls them, newest first
    assert history.read_text(encoding="utf-8") == f"{first}\n{second}\n"
    again = MdiHistory(history)
    assert [again.older(""), again.older("")] == [second, first]


async def test_program_text_follows_the_block_in_execution(service: RunningService) -> None:
    ep = service.endpoint
    lines = LONG_PROGRAM.decode().splitlines()
    async with AsyncClient(ep) as c, HmiApp(ep).run_test(size=SIZE) as pilot:
        await c.upload("long.nc", LONG_PROGRAM)
        app = await started(pilot)
        assert "no program selected" in str(app.program_view.render())
        view = app.program_view

        def agrees() -> bool:
            """The view marks the line the channel table names, with that line's text."""
            line = view.shown.line
            return (view.shown.file == "long.nc" and line > 0
                    and app.channels.cell("ch1", "block").endswith(f"long.nc:{line}")
                    and view.highlighted == lines[line - 1])

        await c.run_program("long.nc")
        await wait_until(pilot, agrees, what=shown(app))
        first_line = view.shown.line
        assert view.border_title == f"ch1 program long.nc, line {first_line}"
        await wait_until(pilot, lambda: agrees() and view.shown.line > first_line,
                         what=shown(app))  # it follows the running program
        assert lines[view.shown.line - 1].startswith("N") and " G1 X" in view.highlighted

        await pilot.press("f4")  # a working channel keeps its mode: the kernel says why
        await wait_until(pilot, lambda: app.message.is_error, what=lambda: app.message.text)
        assert app.message.text.startswith("mode refused: ADS 0x707 NOTREADY")
        assert app.mode_bar.shown_mode == "AUTOMATIC"


async def test_continuous_jog_moves_while_the_key_repeats(
        service: RunningService, monkeypatch: pytest.MonkeyPatch) -> None:
    ep = service.endpoint
    plus, moving = "ch1.ax1.manual_jog_plus_w", "ch1.ax1.manual_moving_r"
    async with AsyncClient(ep) as c, HmiApp(ep).run_test(size=SIZE) as pilot:
        app = await started(pilot)
        await pilot.press("i", "i")  # 1 mm -> 10 mm -> continuous
        assert app.message.text == "jog continuous (while the key is held)"
        assert app.mode_bar.jog_line.render().plain.startswith("jog ch1.X continuous")
        x0 = await c.read("ch1.ax1.command_position_acs")

        # One press without repeats: held, then released when no repeat follows.
        await pilot.press("right_square_bracket")
        await wait_until(pilot, lambda: app.axes.cell("ch1.ax1", "command") != text.mm(x0),
                         what="X moves")
        assert await c.read("ch1.mc_active_mode_r") == 4
        assert await c.read("ch1.ax1.manual_operation_mode_w") == 2  # continuous
        await wait_until(pilot, lambda: app.continuous_jog.held is None, what="released")
        assert await c.read(plus) is False
        assert await c.read("ch1.ax1.command_position_acs") > x0

        # Held (the first repeat is a long way off): space releases it at once.
        monkeypatch.setattr(manual_keys, "FIRST_REPEAT_S", 600.0)
        monkeypatch.setattr(manual_keys, "REPEAT_GAP_S", 600.0)  # renewed meanwhile
        await pilot.press("left_square_bracket")
        await wait_until(pilot, lambda: app.continuous_jog.held is not None)
        assert app.continuous_jog.held.key == "ch1.ax1.manual_jog_minus_w"
        await pilot.press("left_square_bracket")  # a repeat: still the one key held
        await wait_until(pilot, lambda: app.message.text == "ch1: jog X- (held)")
        assert await c.read("ch1.ax1.manual_jog_minus_w") is True
        await pilot.press("space")
        await wait_until(pilot, lambda: app.continuous_jog.held is None)
        assert await c.read("ch1.ax1.manual_jog_minus_w") is False
        await wait_until(pilot, lambda: app.message.text.startswith("jog released"))
        deadline = time.monotonic() + WAIT_S
        while await c.read(moving):  # it brakes under its acceleration, then stands
            assert time.monotonic() < deadline, "X did not stop after the key was released"
            await pilot.pause()


async def test_stopped_service_greys_the_values_and_says_since_when() -> None:
    endpoint = f"tcp://127.0.0.1:{free_port()}"
    first = start_service("--endpoint", endpoint)
    try:
        async with HmiApp(endpoint, timeout_s=0.3).run_test(size=SIZE) as pilot:
            app = await started(pilot)
            assert app.connection.text.startswith("connected to ")
            assert "stale" not in app.channels.classes
            assert first.stop() == 0
            await wait_until(pilot, lambda: NO_REPLY.match(app.connection.text) is not None,
                             what=lambda: app.connection.text)
            for widget in (app.channels, app.axes, app.tooling, app.program_view,
                           app.mode_bar, app.errors):
                assert "stale" in widget.classes, widget
            since = NO_REPLY.match(app.connection.text)
            assert since is not None
            # the clock goes on while the service is away; the moment stays the same
            await wait_until(pilot, lambda: (m := NO_REPLY.match(app.connection.text))
                             is not None and int(m.group(2)) >= 2,
                             what=lambda: app.connection.text)
            assert NO_REPLY.match(app.connection.text).group(1) == since.group(1)
            assert "lost" in app.connection.classes

            second = start_service("--endpoint", endpoint)
            try:
                await wait_until(pilot, lambda: app.connection.text.startswith("connected"),
                                 what=lambda: app.connection.text)
                await wait_until(pilot, lambda: "stale" not in app.channels.classes)
                assert "lost" not in app.connection.classes
                assert "stale" not in app.program_view.classes
            finally:
                assert second.stop() == 0
    finally:
        first.stop()
