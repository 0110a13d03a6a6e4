"""The OPC UA front end: an asyncua server on the service's event loop, over the
``Backend`` that ZeroMQ and ADS serve (docs/opcua.md).

At start it loads the OPC Foundation's nodesets (``nodesets``), builds the CncInterface
(``cnc_interface``) bound to the objects (``binding``), applies security
(``apply_security``) and listens. The kernel knows nothing of it.
"""

from __future__ import annotations

import asyncio
import logging
import time
from pathlib import Path
from typing import Any

from asyncua import Server

from . import address_space_cache as cache
from .alarm_events import build_alarm_events
from .attributes import BoundAttributes
from .binding import VariableBinder
from .channel_methods import build_channel_methods
from .cnc_interface import build_cnc_interface
from .config import endpoint_url
from .limits import OpcUaLimits, apply_limits
from .linked_backend import LinkedBackend
from .machine_tool import build_machine_tool
from .nodesets import asyncua_quiet, load_nodesets
from .security import apply_security
from .security_config import OpcUaSecurity

log = logging.getLogger(__name__)

APPLICATION_URI = "urn:cnc-objects:service"
PRODUCT_URI = "https://github.com/cnc-objects"
VENDOR = "cnc-objects"


class OpcUaServer:
    """The OPC UA front end of one service."""

    def __init__(self, backend: LinkedBackend, security: OpcUaSecurity,
                 limits: OpcUaLimits | None = None) -> None:
        self.backend = backend
        self.security = security
        self.security_note = ""  # what ``apply_security`` serves, for the start-up log
        self.limits = limits or OpcUaLimits()  # [limits] (limits.py)
        self.address: tuple[str, int] = ("", 0)
        self.nodes_left_out = 0  # nodeset nodes asyncua could not import
        self.start_s = 0.0  # how long ``start`` took (nodesets, instances, listening)
        self.cache_note = ""  # where the imported address space came from
        self.binder: VariableBinder | None = None
        self._server: Server | None = None
        self._saving: asyncio.Task[None] | None = None  # a cold start keeping its import

    @property
    def url(self) -> str:
        """``opc.tcp://host:port`` the server listens on."""
        return endpoint_url(*self.address)

    async def start(self, host: str, port: int) -> None:
        """Build the address space and listen on ``host:port`` (0: any free port);
        ``OSError`` when the address cannot be bound."""
        began = time.perf_counter()
        # asyncua logs every node it imports and instantiates at INFO: its warnings only
        asyncua_log = logging.getLogger("asyncua")
        asyncua_log.setLevel(max(asyncua_log.getEffectiveLevel(), logging.WARNING))
        path = cache.cache_file()
        kept = cache.load(path)
        server = Server(iserver=cache.CachedInternalServer(kept[0] if kept else None))
        await server.init()
        server.set_endpoint(endpoint_url(host, port))
        server.set_server_name(f"{VENDOR} CNC")
        await server.set_application_uri(APPLICATION_URI)
        self.security_note = await apply_security(server, self.security, host)
        namespaces = server.nodes.namespace_array
        if kept is None:
            self.nodes_left_out = await load_nodesets(server)
            # pickling the nodes takes about as long as importing them: a thread does it
            # while the server serves (the snapshot is what the import made)
            self._saving = asyncio.create_task(self._keep(
                cache.snapshot(server.iserver.aspace._nodes), await namespaces.read_value(),
                path))
            self.cache_note = f"nodesets imported, keeping them in {path}"
        else:
            # the server's set-up wrote its own; the nodes' indexes are the kept ones,
            # index 1 is this server's application URI (apply_security may set it)
            await namespaces.write_value(
                kept[1][:1] + [server.get_application_uri()] + kept[1][2:])
            with asyncua_quiet():  # the structure classes of the nodesets, made again
                await server.load_data_type_definitions()
            self.cache_note = f"nodesets from {path}"
        binder = VariableBinder(server, self.backend)
        server.iserver.attribute_service = BoundAttributes(server.iserver.aspace, binder)
        await build_cnc_interface(server, binder, self.backend, VENDOR, self._version())
        machine = await build_machine_tool(server, binder, self.backend, VENDOR, PRODUCT_URI)
        await build_alarm_events(server, self.backend, machine)
        await build_channel_methods(server, self.backend, machine)
        server.iserver.end_import()  # built: asyncua's own services from here on
        # last: its guard wraps the session factory the alarm events' methods installed
        apply_limits(server, self.limits)
        with asyncua_quiet():  # its warnings of a server without signing policies
            await server.start()  # (apply_security's choice) and its bind error's trace
        bound = server.bserver
        assert bound is not None  # start() made it
        self.address = (str(bound.hostname), int(bound.port or 0))
        self.binder = binder
        self._server = server
        self.start_s = time.perf_counter() - began

    def _version(self) -> str:
        """The kernel's version, as the object ``cnc_version_r`` serves it."""
        entry = self.backend.space.by_name("cnc_version_r")
        return str(entry.read()) if entry is not None and entry.read is not None else ""

    async def _keep(self, nodes: dict[Any, Any], namespaces: list[str], path: Path) -> None:
        """Write the imported address space to ``path`` on a thread; a failure costs only
        the next start's time, and is logged."""
        began = time.perf_counter()
        try:
            await asyncio.to_thread(cache.save, nodes, namespaces, path)
        except OSError as exc:
            log.warning("OPC UA: cannot keep the imported address space in %s: %s", path, exc)
            return
        log.info("OPC UA: imported address space kept in %s (%.1f s)", path,
                 time.perf_counter() - began)

    async def close(self) -> None:
        """Close every session and stop listening; wait for the imported address space
        to be kept (after a cold start)."""
        if self._saving is not None:
            saving, self._saving = self._saving, None
            await saving
        if self._server is not None:
            server, self._server = self._server, None
            await server.stop()
