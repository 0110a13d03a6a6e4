"""A cold start's import with indexes (``fast_import``) builds the very address space
asyncua's own services build: the same nodes, references in the same order, the same
attribute values."""

from __future__ import annotations

from asyncua import Server
from asyncua.ua import DataValue

from cnc_objects.service.opcua.address_space_cache import CachedInternalServer
from cnc_objects.service.opcua.nodesets import load_nodesets

# ServerStatus and its children (times, build date): written by the server at init
_SERVER_STATUS = {"i=2256", "i=2257", "i=2258", "i=2260", "i=2266"}


async def _imported(indexed: bool) -> dict[str, tuple[object, ...]]:
    iserver = CachedInternalServer(None)
    if not indexed:
        iserver.end_import()  # asyncua's own services from the start
    server = Server(iserver=iserver)
    await server.init()
    await load_nodesets(server)
    iserver.end_import()
    seen: dict[str, tuple[object, ...]] = {}
    for nodeid, node in iserver.aspace._nodes.items():
        key = nodeid.to_string()
        references = tuple(
            (r.ReferenceTypeId.to_string(), r.NodeId.to_string(), r.IsForward, r.NodeClass,
             r.BrowseName, r.TypeDefinition.to_string()) for r in node.references)
        values = () if key in _SERVER_STATUS else tuple(
            (attribute, _value(kept.value)) for attribute, kept in sorted(node.attributes.items()))
        seen[key] = (references, values)
    return seen


def _value(kept: DataValue | None) -> str:
    """The value and status, not the timestamps (each import has its own)."""
    return "None" if kept is None else repr((kept.Value, kept.StatusCode))


async def test_the_indexed_import_builds_what_asyncua_builds() -> None:
    own = await _imported(indexed=False)
    indexed = await _imported(indexed=True)
    assert len(own) > 8000  # the standard address space and the seven nodesets
    assert indexed.keys() == own.keys()
    differing = [key for key in own if indexed[key] != own[key]]
    assert differing == [], [(own[k], indexed[k]) for k in differing[:1]]
