"""Operator data survives: the tool list and the zero offsets written over the wire are
there again after a service restart and after a kernel RESET; a SIGKILL in a burst of
writes leaves a file that loads; a file that cannot be used is moved aside and the
service starts with the configured tables (real services, data directory of their own).
"""

from __future__ import annotations

import json
import signal
import time
from pathlib import Path

import pytest

from cnc_objects.clients import Client
from cnc_objects.objects.operator_data import loads
from cnc_objects.protocol.constants import AdsState
from cnc_objects.testing import serving, start_service
from tests.reliability import figures

INCR = 10_000  # 0.1 um per mm
FILE = "operator-data.json"
G55 = 2  # np_grp[2]
G55_MM = {1: 100.0, 2: 50.0, 3: -10.0}  # axis index -> offset
NODE = "tests/reliability/test_operator_data.py"
WAIT_S = 10.0


def write_operator_data(c: Client, length_mm: float = 42.0) -> None:
    c.write("ch1.wz[5].radius", 3.0 * INCR)
    c.write("ch1.wz[5].laenge", length_mm * INCR)
    c.write("ch1.wz[5].valid", True)
    c.write("ch1.wz[5].name", "drill 6")  # the project's fields of the row are kept too
    c.write("ch1.wz[5].wear", 0.02 * INCR)
    c.write("ch1.wz[5].life_max", 600.0)
    for axis, mm in G55_MM.items():
        c.write(f"ch1.ax{axis}.np_grp[{G55}].v", mm * INCR)


def read_operator_data(c: Client) -> dict[str, object]:
    names = ["ch1.wz[5].valid", "ch1.wz[5].radius", "ch1.wz[5].laenge", "ch1.wz[5].name",
             "ch1.wz[5].wear", "ch1.wz[5].life_max",
             *(f"ch1.ax{a}.np_grp[{G55}].v" for a in G55_MM)]
    return c.read_many(names)


EXPECTED = {"ch1.wz[5].valid": True, "ch1.wz[5].radius": 3.0 * INCR,
            "ch1.wz[5].laenge": 42.0 * INCR, "ch1.wz[5].name": "drill 6",
            "ch1.wz[5].wear": 0.02 * INCR, "ch1.wz[5].life_max": 600.0,
            **{f"ch1.ax{a}.np_grp[{G55}].v": mm * INCR for a, mm in G55_MM.items()}}


def wait_for_file(path: Path, predicate, timeout_s: float = WAIT_S) -> dict:
    """The file's document once ``predicate(document)`` holds (the writer thread writes
    it after the write's reply)."""
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            document = json.loads(path.read_text())
            if predicate(document):
                return document
        except (FileNotFoundError, json.JSONDecodeError):
            pass
        assert time.monotonic() < deadline, f"{path} never showed the write"
        time.sleep(0.001)  # polling a file: there is no event to wait on from outside


def length_in(document: dict) -> float | None:
    for ch in document["channels"]:
        for row in ch.get("tools", ()):
            if row["wz"] == 5:
                return row["length_mm"]
    return None


def test_tool_length_and_g55_survive_a_restart_and_a_kernel_reset(tmp_path: Path) -> None:
    data_dir = tmp_path / "data"
    with serving("--data-dir", str(data_dir)) as service:
        with Client(service.endpoint) as c:
            assert read_operator_data(c)["ch1.wz[5].laenge"] == 0.0
            write_operator_data(c)
            c.write_control(AdsState.RESET)  # the kernel's RESET: a restart of the kernel
            assert read_operator_data(c) == EXPECTED
    with serving("--data-dir", str(data_dir)) as service:
        assert "operator data" in service.log_text and "(loaded)" in service.log_text
        with Client(service.endpoint) as c:
            assert read_operator_data(c) == EXPECTED
            c.reset(1)  # a channel RESET keeps them too
            assert read_operator_data(c) == EXPECTED
    document = json.loads((data_dir / FILE).read_text())
    assert document["format"] == "cnc-objects operator data"
    channel = document["channels"][0]
    assert channel["channel"] == 1
    assert {"wz": 5, "valid": True, "radius_mm": 3.0, "length_mm": 42.0, "name": "drill 6",
            "wear_mm": 0.02, "life_max_s": 600.0} in channel["tools"]
    assert {"np_grp": 2, "name": "G55", "offsets_mm": {"X": 100.0, "Y": 50.0, "Z": -10.0}} \
        in channel["zero_offsets"]


def test_write_latency_and_file_size(tmp_path: Path) -> None:
    data_dir = tmp_path / "data"
    path = data_dir / FILE
    latencies_ms = []
    with serving("--data-dir", str(data_dir)) as service, Client(service.endpoint) as c:
        for k in range(1, 21):
            c.write("ch1.wz[5].laenge", k * INCR)
            written = time.monotonic()
            wait_for_file(path, lambda d, k=k: length_in(d) == k)
            latencies_ms.append((time.monotonic() - written) * 1000)
    size = path.stat().st_size
    latencies_ms.sort()
    print(f"\noperator data: write to file on disk median {latencies_ms[10]:.1f} ms, "
          f"max {latencies_ms[-1]:.1f} ms; file {size} bytes")
    figures.record("operator data: write -> file on disk (median, max), file size",
                   f"{latencies_ms[10]:.1f} ms, {latencies_ms[-1]:.1f} ms, {size} B", NODE)


@pytest.mark.parametrize("kill_after", [150, 400])
def test_sigkill_in_a_burst_of_writes_leaves_a_file_that_loads(tmp_path: Path,
                                                               kill_after: int) -> None:
    data_dir = tmp_path / "data"
    path = data_dir / FILE
    service = start_service("--data-dir", str(data_dir))
    try:
        with Client(service.endpoint, timeout_s=2.0) as c:
            c.write("ch1.wz[5].valid", True)
            for k in range(1, kill_after + 1):
                c.write("ch1.wz[5].laenge", k * INCR)
                if k == kill_after // 2:  # the writer is busy with the burst from here on
                    wait_for_file(path, lambda d: (length_in(d) or 0) >= 1)
            service.process.send_signal(signal.SIGKILL)  # at once after the last reply
    finally:
        assert service.process.wait(WAIT_S) == -signal.SIGKILL
        service.stop()
    data = loads(path.read_text())  # old or new, never torn
    entry = data.channel(1)
    assert entry is not None
    [row] = [r for r in entry.tools or () if r.wz == 5]
    assert row.valid and 1 <= row.length_mm <= kill_after and row.length_mm.is_integer()
    with serving("--data-dir", str(data_dir)) as again, Client(again.endpoint) as c:
        assert c.read("ch1.wz[5].laenge") == row.length_mm * INCR


def test_a_corrupt_file_is_moved_aside_and_the_configured_tables_apply(tmp_path: Path) -> None:
    data_dir = tmp_path / "data"
    data_dir.mkdir()
    (data_dir / FILE).write_text('{"format": "cnc-objects operator data", "version": 1, "chan')
    with serving("--data-dir", str(data_dir)) as service, Client(service.endpoint) as c:
        assert "not loaded: not JSON" in service.log_text
        [aside] = data_dir.glob(f"{FILE}.corrupt-*")
        assert aside.read_text().endswith('"chan')
        assert c.read("ch1.wz[5].laenge") == 0.0
        alarms = c.alarms().active
        assert any(a.id == 90002 and "kept as" in a.text for a in alarms), alarms
        c.write("ch1.wz[5].laenge", 7 * INCR)  # and it keeps data again
        wait_for_file(data_dir / FILE, lambda d: length_in(d) == 7.0)
