"""``make bench`` ADS part, the clients: by-name reads and the whole symbol table.

For each ADS client the tests run (pyads; jisotalo's ads-client on Node, when Node and
its ``node_modules`` are there; py-ads-client): by-name reads of one UINT
(``ch1.mc_command_feed_override_r``) for ``WINDOW_S`` on a fresh connection, in reads/s
(the client's own by-name path: pyads ``read_by_name`` without a type, ads-client
``readValue``, py-ads-client ``read_symbol``), as a ratio to pyads'; then, for pyads and
ads-client, upload the symbol table and read every symbol once, in seconds.
"""

from __future__ import annotations

import ctypes
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pyads
from pyads.pyads_ex import adsGetSymbolInfo

from cnc_objects.testing.process import start_service

from .common import BENCH_MACHINE

NAME = "ch1.mc_command_feed_override_r"
WINDOW_S = 2.0
LOCAL_NET_ID = "127.0.0.1.1.32"
NODE_DIR = Path(__file__).resolve().parents[1] / "tests" / "ads_clients" / "node"


def _pyads_reads(plc: pyads.Connection) -> float:
    count, until = 0, time.perf_counter() + WINDOW_S
    while time.perf_counter() < until:
        plc.read_by_name(NAME)
        count += 1
    return count / WINDOW_S


def _pyads_upload_read_all(plc: pyads.Connection) -> tuple[int, float]:
    started = time.perf_counter()
    symbols = plc.get_all_symbols()
    for symbol in symbols:
        if symbol.plc_type is not None:
            symbol.read()
        else:  # a struct: pyads has no type for it; its bytes, the size from 0xF009
            info = adsGetSymbolInfo(plc._port, plc._adr, symbol.name)
            plc.read(symbol.index_group, symbol.index_offset, ctypes.c_ubyte * info.size)
    return len(symbols), time.perf_counter() - started


def _node(check: str, host: str, port: int, net_id: str) -> dict | None:
    node = shutil.which("node")
    if node is None or not (NODE_DIR / "node_modules" / "ads-client").is_dir():
        return None
    ran = subprocess.run([node, "check.js", check, host, str(port), net_id], cwd=NODE_DIR,
                         capture_output=True, text=True, timeout=300, check=False)
    out = json.loads(ran.stdout.strip().splitlines()[-1])
    return out["result"] if out.get("ok") else None


def _py_ads_client_reads(host: str, net_id: str) -> float | None:
    try:
        from py_ads_client import UINT, ADSClient, ADSSymbol
    except ImportError:
        return None
    client = ADSClient(local_ams_net_id="127.0.0.1.1.33")
    client.open(target_ip=host, target_ams_net_id=net_id)
    try:
        symbol = ADSSymbol(NAME, UINT)
        count, until = 0, time.perf_counter() + WINDOW_S
        while time.perf_counter() < until:
            client.read_symbol(symbol)
            count += 1
        return count / WINDOW_S
    finally:
        client.close()


def main() -> None:
    """Measure and print the table."""
    with tempfile.TemporaryDirectory() as tmp:
        machine = Path(tmp) / "bench.toml"
        machine.write_text(BENCH_MACHINE)
        service = start_service("--clock", "realtime", "--config", str(machine), ads=True)
    pyads.open_port()
    pyads.set_local_address(LOCAL_NET_ID)
    try:
        host, port = service.ads_address  # type: ignore[misc]
        net_id = service.ams_net_id
        plc = pyads.Connection(net_id, 851, host)
        plc.open()
        try:
            reads = {"pyads": _pyads_reads(plc)}
            uploads = {"pyads": _pyads_upload_read_all(plc)}
        finally:
            plc.close()
        node_reads = _node("reads_per_second", host, port, net_id)
        if node_reads is not None:
            reads["ads-client (Node)"] = node_reads["readsPerSecond"]
        node_upload = _node("upload_read_all", host, port, net_id)
        if node_upload is not None:
            uploads["ads-client (Node)"] = (node_upload["read"], node_upload["seconds"])
        py_ads = _py_ads_client_reads(host, net_id)
        if py_ads is not None:
            reads["py-ads-client"] = py_ads
    finally:
        pyads.close_port()
        service.stop()
    base = reads["pyads"]
    print(f"\nADS clients, by-name reads of {NAME} on a fresh connection ({WINDOW_S:.0f} s each)\n")
    print(f"{'client':24} {'reads/s':>10} {'vs pyads':>9}")
    for client, rate in reads.items():
        print(f"{client:24} {rate:10.0f} {rate / base:9.2f}")
    print(f"\n{'upload + read every symbol':28} {'symbols':>8} {'seconds':>8}")
    for client, (count, seconds) in uploads.items():
        print(f"{client:28} {count:8d} {seconds:8.2f}")
    missing = {"ads-client (Node)"} - set(reads)
    if missing:
        print("(ads-client not measured: Node.js or tests/ads_clients/node/node_modules missing; "
              "run npm ci there)", file=sys.stderr)
