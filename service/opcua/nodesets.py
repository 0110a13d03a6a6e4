"""The OPC Foundation's NodeSet2 files this front end serves, in the order they load.

Vendored unchanged from the OPC Foundation's UA-Nodeset repository (MIT, the license in
each file's header and in ``nodesets/LICENSE``; versions in docs/opcua.md). Each file
needs the ones before it (its ``RequiredModel`` entries): DI, IA and Machinery under
Jobs, ISA95-JOBCONTROL under Machinery/Jobs, all of them under MachineTool (40501-1);
CNC (40502) needs only the base namespace.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from asyncua import Server

NODESET_DIR = Path(__file__).with_name("nodesets")

#: (namespace URI, file), in dependency order.
NODESETS: tuple[tuple[str, str], ...] = (
    ("http://opcfoundation.org/UA/DI/", "Opc.Ua.Di.NodeSet2.xml"),
    ("http://opcfoundation.org/UA/IA/", "Opc.Ua.IA.NodeSet2.xml"),
    ("http://opcfoundation.org/UA/Machinery/", "Opc.Ua.Machinery.NodeSet2.xml"),
    ("http://opcfoundation.org/UA/ISA95-JOBCONTROL_V2/", "opc.ua.isa95-jobcontrol.nodeset2.xml"),
    ("http://opcfoundation.org/UA/Machinery/Jobs/", "Opc.Ua.Machinery.Jobs.Nodeset2.xml"),
    ("http://opcfoundation.org/UA/MachineTool/", "Opc.Ua.MachineTool.NodeSet2.xml"),
    ("http://opcfoundation.org/UA/CNC", "Opc.Ua.CNC.NodeSet.xml"),
)
CNC_URI = NODESETS[-1][0]
MACHINE_TOOL_URI = NODESETS[-2][0]
#: The CNC nodeset (1.0.0, 2017) as published carries an example instance of
#: CncInterfaceType named "test" under Objects (its ns=1;i=5008), with empty lists: not a
#: part of the model, and a plant's client would show it beside the real CncInterface.
#: It is removed after the import (docs/opcua.md "The nodesets").
CNC_EXAMPLE_INSTANCE = 5008


class Counted(logging.Handler):
    """Counts what asyncua logs at ERROR and above instead of printing it."""

    def __init__(self) -> None:
        super().__init__(logging.ERROR)
        self.count = 0

    def emit(self, record: logging.LogRecord) -> None:
        self.count += 1


@contextmanager
def asyncua_quiet() -> Iterator[Counted]:
    """asyncua's log kept out of the service's while the block runs (a warning per
    structure class it builds from a nodeset, an error per node it cannot import): the
    errors are counted instead."""
    quiet = logging.getLogger("asyncua")
    counted = Counted()
    level, propagate = quiet.level, quiet.propagate
    quiet.setLevel(logging.ERROR)
    quiet.propagate = False
    quiet.addHandler(counted)
    try:
        yield counted
    finally:
        quiet.removeHandler(counted)
        quiet.setLevel(level)
        quiet.propagate = propagate


async def load_nodesets(server: Server) -> int:
    """Import every nodeset into ``server`` in dependency order; the nodes asyncua cannot
    import are left out, not fatal (Machinery/Jobs' OptionSet structures,
    docs/opcua.md "Departures"): their count is returned."""
    with asyncua_quiet() as counted:
        for _, name in NODESETS:
            await server.import_xml(str(NODESET_DIR / name), strict_mode=False)
        cnc = await server.get_namespace_index(CNC_URI)
        await server.delete_nodes([server.get_node(f"ns={cnc};i={CNC_EXAMPLE_INSTANCE}")],
                                  recursive=True)
    return counted.count
