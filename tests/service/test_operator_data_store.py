"""The operator data store in-process: a real kernel's cycle hook feeds it; it writes on
a change of the tables only (not while programs run), loads what it wrote, and moves a
file that does not fit the machine aside."""

from __future__ import annotations

from pathlib import Path

from cnc_objects.objects.operator_data import loads
from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.alarms import AlarmLog
from cnc_objects.service.kernel.commands_tooling import SetToolData, SetZeroOffset
from cnc_objects.service.kernel.nc.tool_data import ToolField
from cnc_objects.service.kernel.state import Snapshot
from cnc_objects.service.storage.operator_data_store import UNREADABLE_ID, OperatorDataStore
from tests.support.kernel import KernelHarness

INCR = 10_000


def test_written_on_a_change_only_and_loaded_again(tmp_path: Path) -> None:
    path = tmp_path / "operator-data.json"
    with KernelHarness() as h:
        store = OperatorDataStore(path, h.config)
        hook = h.kernel.on_cycle_end
        assert hook is not None

        def both(s):  # the harness's hook and the store's, as the service chains them
            hook(s)
            store.observe(s)

        h.kernel.on_cycle_end = both
        store.start()
        h.run("T2 M6 D2 G54 G01 X10 F6000\nG55 Y5\nM30\n")  # reads the tables, writes none
        assert store.writes == 0 and not path.exists()
        assert h.command(SetToolData(0, 5, ToolField.LENGTH, 42.0 * INCR)) is None
        assert h.command(SetZeroOffset(0, 2, 0, 100.0 * INCR)) is None
        h.run("G01 X0\nM30\n")  # a cycle after both
        store.close()
        assert store.writes >= 1
    data = loads(path.read_text())
    entry = data.channel(1)
    assert entry is not None and entry.tools is not None and entry.zero_offsets is not None
    assert [(r.wz, r.length_mm) for r in entry.tools if r.wz == 5] == [(5, 42.0)]
    [g55] = [g for g in entry.zero_offsets if g.np_grp == 2]
    assert g55.offsets_mm["X"] == 100.0
    tables = OperatorDataStore(path, build_config().machine).load()
    assert tables[0] is not None and tables[0].tools.row(5).length_01um == 42.0 * INCR
    assert tables[0].zero_offsets.offset_01um(2, 0) == 100.0 * INCR


def test_a_file_that_does_not_fit_the_machine_is_moved_aside(tmp_path: Path) -> None:
    head = '{"format": "cnc-objects operator data", "version": 1, "channels": '
    for body, words in [
        ('[{"channel": 9, "tools": []}]', "channel 9 is not configured"),
        ('[{"channel": 1, "tools": [{"wz": 33}]}]', "wz[33] is beyond the tool list (1..32)"),
        ('[{"channel": 1, "zero_offsets": [{"np_grp": 10, "offsets_mm": {}}]}]',
         "np_grp[10] is beyond the zero offset table (1..9)"),
        ('[{"channel": 1, "zero_offsets": [{"np_grp": 1, "offsets_mm": {"Q": 1}}]}]',
         "names axis Q; the channel has X, Y, Z"),
    ]:
        directory = tmp_path / str(len(list(tmp_path.iterdir())))
        directory.mkdir()
        path = directory / "operator-data.json"
        path.write_text(head + body + "}")
        alarms = AlarmLog()
        assert OperatorDataStore(path, build_config().machine).load(alarms) == []
        assert not path.exists() and len(list(directory.glob("*.corrupt-*"))) == 1
        [alarm] = alarms.view.active
        assert alarm.id == UNREADABLE_ID and words in alarm.text, alarm.text


def test_a_programs_zero_offset_write_is_not_kept(tmp_path: Path) -> None:
    """``V.G.NP[j]`` lasts until the list is read again (ISG: "explicit request or
    start-up"): the store keeps the operator's values; an operator write after it is
    kept, the program's value beside it is not."""
    path = tmp_path / "operator-data.json"
    with KernelHarness() as h:
        store = OperatorDataStore(path, h.config)
        hook = h.kernel.on_cycle_end
        assert hook is not None

        def both(s: Snapshot) -> None:  # the harness's hook and the store's, as the service chains them
            hook(s)
            store.observe(s)

        h.kernel.on_cycle_end = both
        store.start()
        run = h.run("V.G.NP[1].V.X = 7\nG54 G01 X0 F6000\nM30\n")
        assert run.channel.tooling.zero_offsets.offset_mm(1, 0) == 7.0
        assert store.writes == 0 and not path.exists()
        assert h.command(SetZeroOffset(0, 1, 1, 3.0 * INCR)) is None  # G54 Y, operator
        run = h.run("G01 X0\nM30\n")  # a cycle after it
        assert run.channel.tooling.zero_offsets.offset_mm(1, 1) == 3.0
        assert run.channel.tooling.zero_offsets.offset_mm(1, 0) == 7.0  # still in effect
        store.close()
        assert store.writes >= 1
    entry = loads(path.read_text()).channel(1)
    assert entry is not None and entry.zero_offsets is not None
    [g54] = [g for g in entry.zero_offsets if g.np_grp == 1]
    assert (g54.offsets_mm["X"], g54.offsets_mm["Y"]) == (0.0, 3.0)
