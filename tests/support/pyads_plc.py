"""A service with ADS/TCP and pyads connections to it, for the tests that are a PLC or an
ADS tool: ``pyads_service`` starts it, opens pyads' AMS router on ``local_net_id`` and one
connection per AMS port, and takes everything down again (the service must exit 0).
``plc_machine`` is the one-channel machine whose M functions the PLC acknowledges."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path

import pyads

from cnc_objects.testing import ServiceProcess, start_service


def plc_machine(m_synch: dict[str, str]) -> str:
    """The TOML of one channel (X, Y, Z) whose M functions ``m_synch`` lists wait for the
    PLC's acknowledge (``auto_acknowledge = false``)."""
    kinds = ", ".join(f'"{number}" = "{kind}"' for number, kind in m_synch.items())
    return f"""
[[channels]]
id = 1
name = "main"
axes = [
    {{name = "X", logical_number = 1, link_to = 1}},
    {{name = "Y", logical_number = 2, link_to = 2}},
    {{name = "Z", logical_number = 3, link_to = 3}},
]
[channels.techno]
auto_acknowledge = false
m_synch = {{{kinds}}}
"""


@contextlib.contextmanager
def pyads_service(
    work: Path, local_net_id: str, *args: str, config: str | None = None,
    ports: tuple[int, ...] = (851,),
) -> Iterator[tuple[ServiceProcess, list[pyads.Connection]]]:
    """A service (``args``: its options; ``config``: a machine TOML written to ``work``)
    and a pyads connection to each of ``ports``, in order."""
    if config is not None:
        path = work / "machine.toml"
        path.write_text(config)
        args = (*args, "--config", str(path))
    service = start_service(*args, program_dir=work / "programs", ads=True)
    connections: list[pyads.Connection] = []
    try:
        net_id, (ip, _) = service.ams_net_id, service.ads_address  # type: ignore[misc]
        pyads.open_port()
        pyads.set_local_address(local_net_id)
        pyads.add_route(net_id, ip)
        for port in ports:
            connection = pyads.Connection(net_id, port, ip)
            connection.open()
            connections.append(connection)
        yield service, connections
    finally:
        for connection in connections:
            connection.close()
        pyads.close_port()
        assert service.stop() == 0, service.log_text
