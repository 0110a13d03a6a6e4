"""Import the nodesets once, at installation: ``python -m cnc_objects.service.opcua.prepare``
(``make run`` does it) writes the address space cache a cold start would write, so the
service's first start is a warm one (docs/opcua.md, "Start-up").

Prints where the cache is and exits 0; exits 1 with one line when it cannot be written
(the service then imports at its first start, as without this step).
"""

from __future__ import annotations

import asyncio
import logging
import sys
import time
from pathlib import Path

from asyncua import Server

from . import address_space_cache as cache
from .nodesets import load_nodesets


async def prepare(path: Path) -> None:
    """Import the nodesets into a server of their own and keep them at ``path``
    (``OSError`` when it cannot be written)."""
    logging.getLogger("asyncua").setLevel(logging.WARNING)
    iserver = cache.CachedInternalServer(None)
    server = Server(iserver=iserver)
    await server.init()
    await load_nodesets(server)
    cache.save(iserver.aspace._nodes, await server.nodes.namespace_array.read_value(), path)


def main() -> int:
    """The command: import and keep unless this asyncua's and nodesets' cache exists."""
    path = cache.cache_file()
    if cache.load(path) is not None:
        print(f"OPC UA address space already kept in {path}")
        return 0
    began = time.perf_counter()
    try:
        asyncio.run(prepare(path))
    except OSError as exc:
        print(f"cannot keep the OPC UA address space in {path}: {exc}", file=sys.stderr)
        return 1
    print(f"OPC UA address space kept in {path} ({time.perf_counter() - began:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
