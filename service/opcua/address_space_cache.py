"""The imported address space kept on disk: a warm start loads it instead of building
the standard address space and importing the nodesets again (docs/opcua.md, "Start-up").

The cache is one file per key: the asyncua version and the nodesets' bytes hashed
(``cache_key``), so a changed nodeset or asyncua never loads a stale cache. It holds every
node pickled on its own, and the server loads a node only when it is first looked up
(``LazyNodes``, as asyncua's own shelf of the standard address space does): a start reads
the few thousand nodes it touches, not all of them. It is written once (to a temporary
file, then renamed: services that start side by side never read half a file) after a
cold start's import, before any instance or callback exists.

Not kept: callables (method callbacks, which the server's own set-up sets again) and
values of the structure classes asyncua generates at import (the default values of
some type members, served as null from the cache; the instances' values are bound).
"""

from __future__ import annotations

import hashlib
import io
import logging
import os
import pickle
import tempfile
from collections.abc import Iterator, MutableMapping
from importlib.metadata import version
from pathlib import Path
from typing import Any

from asyncua import ua
from asyncua.server.address_space import (
    AttributeValue,
    NodeData,
    NodeManagementService,
    ViewService,
)
from asyncua.server.internal_server import InternalServer

from .fast_import import importing_services
from .nodesets import NODESET_DIR, NODESETS

log = logging.getLogger(__name__)

CACHE_FORMAT = 2  # bump when what is pickled changes (2: without the CNC example "test")
CACHE_DIR_ENV = "CNC_OPCUA_CACHE_DIR"
_GENERATED = "asyncua.common.structures104"  # where asyncua's import makes its classes


def cache_dir() -> Path:
    """``$CNC_OPCUA_CACHE_DIR``, else ``$XDG_CACHE_HOME/cnc-objects/opcua``, else
    ``~/.cache/cnc-objects/opcua``."""
    own = os.environ.get(CACHE_DIR_ENV)
    if own:
        return Path(own)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "cnc-objects" / "opcua"


def cache_key() -> str:
    """The nodesets' bytes, asyncua's version and the cache format, hashed."""
    digest = hashlib.sha256(f"{CACHE_FORMAT} asyncua {version('asyncua')}".encode())
    for _, name in NODESETS:
        digest.update((NODESET_DIR / name).read_bytes())
    return digest.hexdigest()[:32]


def cache_file() -> Path:
    """Where the address space of these nodesets is kept."""
    return cache_dir() / f"address-space-{cache_key()}.pickle"


class _NodePickler(pickle.Pickler):
    """Pickles a node without its callables and generated structure values."""

    def reducer_override(self, obj: Any) -> Any:
        if isinstance(obj, type):
            return NotImplemented
        if callable(obj) or type(obj).__module__ == _GENERATED:
            return type(None), ()
        return NotImplemented


def _pickled(node: NodeData) -> bytes:
    buffer = io.BytesIO()
    _NodePickler(buffer, pickle.HIGHEST_PROTOCOL).dump(node)
    return buffer.getvalue()


def snapshot(nodes: MutableMapping[ua.NodeId, NodeData]) -> dict[ua.NodeId, NodeData]:
    """The nodes as they are now, for ``save`` on another thread while the server goes
    on: each node with its own attribute and reference containers (the server adds
    references to the type nodes and writes values in place), the values themselves
    shared (a write replaces a DataValue, never changes it). Callables are left out, as
    ``save`` would leave them (there are none right after an import)."""
    return {nodeid: _node_copy(node) for nodeid, node in nodes.items()}


def _node_copy(node: NodeData) -> NodeData:
    copy = NodeData(node.nodeid)
    copy.attributes = {attribute: AttributeValue(kept.value)
                       for attribute, kept in node.attributes.items()}
    copy.references = list(node.references)
    return copy


def save(nodes: MutableMapping[ua.NodeId, NodeData], namespaces: list[str], path: Path
         ) -> None:
    """Write ``nodes`` and the server's ``namespaces`` (its NamespaceArray, which the
    server's set-up writes anew) to ``path`` atomically; ``OSError`` when it cannot."""
    table = {nodeid.to_string(): _pickled(node) for nodeid, node in nodes.items()}
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".part")
    try:
        with os.fdopen(handle, "wb") as out:
            pickle.dump((CACHE_FORMAT, namespaces, table), out, pickle.HIGHEST_PROTOCOL)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def load(path: Path) -> tuple[LazyNodes, list[str]] | None:
    """The nodes and namespaces kept at ``path``; None when there is no usable cache."""
    try:
        with path.open("rb") as kept:
            form, namespaces, table = pickle.load(kept)
    except (FileNotFoundError, NotADirectoryError):  # none kept (yet)
        return None
    except Exception as exc:  # a damaged cache is rebuilt, never fatal
        log.warning("OPC UA address space cache %s unusable (%s): importing again", path, exc)
        return None
    if form != CACHE_FORMAT or not isinstance(table, dict):
        return None
    return LazyNodes(table), list(namespaces)


class LazyNodes(MutableMapping[ua.NodeId, NodeData]):
    """The address space's node table over the pickled nodes: a node is unpickled when
    first looked up; nodes added later live in memory only. Iterates the nodes looked up
    or added so far (as asyncua's shelf does)."""

    def __init__(self, pickled: dict[str, bytes]) -> None:
        self._pickled = pickled
        self._nodes: dict[ua.NodeId, NodeData] = {}

    def __getitem__(self, key: ua.NodeId) -> NodeData:
        try:
            return self._nodes[key]
        except KeyError:
            data = self._pickled.pop(key.to_string())  # KeyError: no such node
            node: NodeData = pickle.loads(data)
            self._nodes[key] = node
            return node

    def __setitem__(self, key: ua.NodeId, value: NodeData) -> None:
        self._pickled.pop(key.to_string(), None)
        self._nodes[key] = value

    def __delitem__(self, key: ua.NodeId) -> None:
        if self._pickled.pop(key.to_string(), None) is None:
            del self._nodes[key]
        else:
            self._nodes.pop(key, None)

    def __contains__(self, key: object) -> bool:
        return key in self._nodes or (
            isinstance(key, ua.NodeId) and key.to_string() in self._pickled)

    def __iter__(self) -> Iterator[ua.NodeId]:
        return iter(list(self._nodes))

    def __len__(self) -> int:
        return len(self._nodes)


class CachedInternalServer(InternalServer):  # type: ignore[misc]  # asyncua is Any to mypy
    """asyncua's internal server whose standard address space comes from the cache's
    nodes (the nodesets' included) when it is given them."""

    def __init__(self, nodes: LazyNodes | None) -> None:
        super().__init__()
        self.cached_nodes = nodes
        # the import and the instances are built with indexes (fast_import)
        self.node_mgt_service, self.view_service = importing_services(self.aspace)

    def end_import(self) -> None:
        """Back to asyncua's own node management and browsing (once the address space
        is built)."""
        self.node_mgt_service = NodeManagementService(self.aspace)
        self.view_service = ViewService(self.aspace)

    async def load_standard_address_space(self, shelf_file: Path | None = None) -> None:
        """The cached nodes, else asyncua's standard address space."""
        if self.cached_nodes is None:
            await super().load_standard_address_space(shelf_file)
            return
        self.aspace._nodes = self.cached_nodes
