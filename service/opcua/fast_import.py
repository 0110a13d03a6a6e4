"""asyncua's node management and browsing with indexes, for a cold start's import only
(docs/opcua.md, "Start-up").

A cold start builds the standard address space and imports the seven nodesets through
asyncua's node management service: some 8 000 nodes and 32 000 references. asyncua makes
each reference unique by scanning every reference its node already has (the type nodes
gather thousands: every instance points back at its type), and the importer's
reverse-reference pass browses each new node with "reference type and its subtypes",
walking the reference type tree again for every reference. Both are quadratic; the
answers are the same with an index of each node's references and the subtype sets kept
until the address space changes. Measured on the 2-core machine: the import 1.27 s ->
0.97 s with the subtype sets alone, and see docs/opcua.md for the whole.

The server uses them while it imports and goes back to asyncua's own services after
(``CachedInternalServer.end_import``): at run time nodes are few and added rarely, and
asyncua's services are what its tests cover.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

from asyncua import ua
from asyncua.server.address_space import (
    AddressSpace,
    NodeData,
    NodeManagementService,
    ViewService,
)

log = logging.getLogger(__name__)

_NULL_NODE = ua.NodeId(ua.ObjectIds.Null)
_HAS_SUBTYPE = ua.NodeId(ua.ObjectIds.HasSubtype)
_ReferenceKey = tuple[ua.NodeId, ua.NodeId]  # (reference type, target)


class IndexedNodeManagement(NodeManagementService):  # type: ignore[misc]  # asyncua is Any
    """asyncua's node management whose unique-reference check looks the reference up in
    an index of the node's references instead of scanning them. ``changed`` is called
    whenever a HasSubtype reference is added or anything is deleted (what the subtype
    sets are made of)."""

    def __init__(self, aspace: AddressSpace, changed: Callable[[], None]) -> None:
        super().__init__(aspace)
        self._changed = changed
        # node id -> (the node, how many references the index saw, (type, target) ->
        # direction of the first such reference, as asyncua's scan finds it)
        self._index: dict[ua.NodeId, tuple[NodeData, int, dict[_ReferenceKey, bool]]] = {}

    def _references_of(self, nodedata: NodeData) -> dict[_ReferenceKey, bool]:
        kept = self._index.get(nodedata.nodeid)
        if kept is not None and kept[0] is nodedata and kept[1] == len(nodedata.references):
            return kept[2]
        # first time, or the list changed behind the index: read it again
        directions: dict[_ReferenceKey, bool] = {}
        for reference in nodedata.references:
            directions.setdefault((reference.ReferenceTypeId, reference.NodeId),
                                  reference.IsForward)
        self._index[nodedata.nodeid] = (nodedata, len(nodedata.references), directions)
        return directions

    def _add_unique_reference(self, nodedata: NodeData, desc: ua.ReferenceDescription
                              ) -> ua.StatusCode:
        """As asyncua's: a conflicting direction is refused, a duplicate kept once."""
        directions = self._references_of(nodedata)
        key = (desc.ReferenceTypeId, desc.NodeId)
        forward = directions.get(key)
        if forward is None:
            nodedata.references.append(desc)
            directions[key] = desc.IsForward
            self._index[nodedata.nodeid] = (nodedata, len(nodedata.references), directions)
            if desc.ReferenceTypeId == _HAS_SUBTYPE:  # the only kind the subtype sets read
                self._changed()
        elif forward != desc.IsForward:
            log.error("Cannot add conflicting reference %s ", str(desc))
            return ua.StatusCode(ua.StatusCodes.BadReferenceNotAllowed)
        return ua.StatusCode()

    def delete_nodes(self, *args: Any, **kwargs: Any) -> list[ua.StatusCode]:
        self._index.clear()
        self._changed()
        deleted: list[ua.StatusCode] = super().delete_nodes(*args, **kwargs)
        return deleted

    def delete_references(self, *args: Any, **kwargs: Any) -> list[ua.StatusCode]:
        self._index.clear()
        self._changed()
        deleted: list[ua.StatusCode] = super().delete_references(*args, **kwargs)
        return deleted


class SubtypeKeepingView(ViewService):  # type: ignore[misc]  # asyncua is Any to mypy
    """asyncua's browsing with each reference type's subtypes kept until ``forget``."""

    def __init__(self, aspace: AddressSpace) -> None:
        super().__init__(aspace)
        self._subtypes: dict[ua.NodeId, frozenset[ua.NodeId]] = {}

    def forget(self) -> None:
        """The address space changed: the subtype sets are made again when asked."""
        self._subtypes.clear()

    def _suitable_reftype(self, ref1: ua.NodeId, ref2: ua.NodeId, subtypes: bool) -> bool:
        if ref1 == _NULL_NODE or ref1 == ref2:
            return True
        if not subtypes:
            return False
        known = self._subtypes.get(ref1)
        if known is None:
            known = self._subtypes[ref1] = frozenset(self._get_sub_ref(ref1))
        return ref2 in known


def importing_services(aspace: AddressSpace) -> tuple[IndexedNodeManagement,
                                                      SubtypeKeepingView]:
    """The node management and view services for an import into ``aspace``."""
    view = SubtypeKeepingView(aspace)
    return IndexedNodeManagement(aspace, view.forget), view
