"""OPC UA variables bound to CNC objects: read, subscribed and written through the
``Backend``, as the ADS front end reads, subscribes and writes them.

- Read: the variable's Value attribute has a read callback (asyncua's
  ``set_attribute_value_callback``): each Read calls the objects' getters (the ones ADS
  reads and the notification hub samples, ``Backend.direct_read``) on the event loop,
  from the kernel's newest snapshot, and turns the raw values into the OPC UA value
  (``sources.Source``).
- Subscribe: a monitored item on a bound variable joins the variable's feed of its
  sampling interval (``feeds``: on-change subscriptions at the ``NotificationHub``).
- Write: ``write`` checks the session's role (``roles.role_of``, the access policy
  of every front end: ``role_to_write``), the variant type and the range, then writes
  through ``Backend.decode_writes`` and ``apply_writes`` and answers when the kernel has
  applied it: BadUserAccessDenied, BadTypeMismatch, BadOutOfRange (the kernel's own
  refusal of a value included) and nothing changes.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable
from typing import Any

from asyncua import Server, ua
from asyncua.crypto.permission_rules import User

from cnc_objects.objects import Entry
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.roles import role_to_write

from .feeds import BoundVariable, Feeds
from .linked_backend import LinkedBackend
from .roles import role_of
from .sources import Source
from .values import eu_information

log = logging.getLogger(__name__)

_S = ua.StatusCodes
_E = AdsReturnCode
#: The ADS code of a refused write -> the OPC UA status that answers it.
WRITE_STATUS: dict[int, int] = {
    _E.DEVICE_INVALIDDATA: _S.BadOutOfRange,
    _E.DEVICE_INVALIDPARM: _S.BadOutOfRange,
    _E.DEVICE_INVALIDSIZE: _S.BadTypeMismatch,
    _E.DEVICE_INVALIDACCESS: _S.BadNotWritable,
    _E.DEVICE_NOTREADY: _S.BadInvalidState,
    _E.DEVICE_INVALIDSTATE: _S.BadInvalidState,
}
_READ_ONLY = ua.AccessLevel.CurrentRead.mask
_READ_WRITE = ua.AccessLevel.CurrentRead.mask | ua.AccessLevel.CurrentWrite.mask
_VALUE = ua.AttributeIds.Value


class VariableBinder:
    """Binds OPC UA variables of ``server`` to the objects of ``backend``."""

    def __init__(self, server: Server, backend: LinkedBackend) -> None:
        self.server = server
        self.backend = backend
        self.variables: dict[ua.NodeId, BoundVariable] = {}
        self._aspace = server.iserver.aspace
        self.feeds = Feeds(backend)

    # ------------------------------------------------------------ binding

    async def bind(self, node_id: ua.NodeId, source: Source) -> BoundVariable:
        """Serve ``node_id``'s value from ``source``: its objects must exist
        (``KeyError`` names the one that does not); its access level says whether it may
        be written; its EngineeringUnits and EURange properties, where it has them, are
        set from ``source``."""
        space = self.backend.space
        entries = []
        for name in source.objects:
            entry = space.by_name(name)
            if entry is None or entry.read is None:
                raise KeyError(f"OPC UA variable {node_id.to_string()}: no readable object {name}")
            entries.append(entry)
        getters = tuple(self._getter(e) for e in entries)
        var = BoundVariable(node_id, source, tuple(entries), getters)
        self.variables[node_id] = var
        level = _READ_WRITE if source.write_object is not None else _READ_ONLY
        for attr in (ua.AttributeIds.AccessLevel, ua.AttributeIds.UserAccessLevel):
            await self._aspace.write_attribute_value(
                node_id, attr, ua.DataValue(ua.Variant(level, ua.VariantType.Byte)))
        await self._aspace.write_attribute_value(
            node_id, ua.AttributeIds.ValueRank,
            ua.DataValue(ua.Variant(1 if source.array else -1, ua.VariantType.Int32)))
        self._aspace.set_attribute_value_callback(node_id, _VALUE, lambda n, a: var.value())
        node = self._aspace[node_id]
        node.attributes[_VALUE].datachange_callbacks = self.feeds.watch(var)
        await self._properties(node_id, source)
        return var

    def _getter(self, entry: Entry) -> Callable[[], Any]:
        """The getter ADS reads and the hub samples (``Backend.direct_read``), else a
        read through ``Backend.read_value`` decoded."""
        obj = entry.obj
        direct = self.backend.direct_read(obj.port, obj.group, obj.offset, obj.dtype.size)
        if direct is not None:
            return direct[0]
        read, dtype = self.backend.read_value, obj.dtype

        def through_backend() -> Any:
            code, data = read(obj.port, obj.group, obj.offset, dtype.size)
            if code:
                raise RuntimeError(f"{obj.name}: ADS code {code:#x}: {data!r}")
            return dtype.decode(data)

        return through_backend

    async def _properties(self, node_id: ua.NodeId, source: Source) -> None:
        """EngineeringUnits and EURange of an AnalogItem (added when the instance lacks
        them: both are optional or mandatory by type; we always give them)."""
        if source.unit is None:
            return
        node = self.server.get_node(node_id)
        idx = 0
        units = await _child(node, "EngineeringUnits")
        if units is None:
            units = await node.add_property(idx, "EngineeringUnits", eu_information(source.unit))
        else:
            await units.write_value(eu_information(source.unit))
        if source.limits is not None:
            low, high = source.limits
            eu_range = ua.Range(Low=low, High=high)
            found = await _child(node, "EURange")
            if found is None:
                await node.add_property(idx, "EURange", eu_range)
            else:
                await found.write_value(eu_range)

    # ------------------------------------------------------------ writes

    async def write(self, node_id: ua.NodeId, value: ua.DataValue, user: User | None
                    ) -> ua.StatusCode:
        """Write ``value`` to a bound variable as the session of ``user`` may."""
        var = self.variables.get(node_id)
        if var is None or var.source.write_object is None or var.source.to_raw is None:
            return ua.StatusCode(_S.BadNotWritable)
        entry = self.backend.space.by_name(var.source.write_object)
        if entry is None or entry.write is None:
            return ua.StatusCode(_S.BadNotWritable)
        obj = entry.obj
        role = role_of(user)
        if role is not None and not role.may(role_to_write(obj.port, obj.group)):
            return ua.StatusCode(_S.BadUserAccessDenied)
        variant = value.Value
        if variant is None or variant.VariantType != var.source.variant:
            return ua.StatusCode(_S.BadTypeMismatch)
        try:
            data = obj.dtype.encode(var.source.to_raw(variant.Value))
        except (ValueError, OverflowError):
            return ua.StatusCode(_S.BadOutOfRange)
        except TypeError:
            return ua.StatusCode(_S.BadTypeMismatch)
        code, message, items = self.backend.decode_writes(obj.port, obj.group, obj.offset, data)
        if code:
            log.debug("OPC UA write to %s refused: %s", obj.name, message)
            return ua.StatusCode(WRITE_STATUS.get(code, _S.BadInternalError))
        done: asyncio.Future[list[tuple[int, str]]] = asyncio.get_running_loop().create_future()
        self.backend.apply_writes(items, done.set_result, holder=("opcua", id(user)))
        results = await done
        for code, message in results:
            if code:
                log.debug("OPC UA write to %s refused: %s", obj.name, message)
                return ua.StatusCode(WRITE_STATUS.get(code, _S.BadInternalError))
        return ua.StatusCode(_S.Good)


async def _child(node: Any, name: str) -> Any:
    """The child of ``node`` browsed as ``name`` (any namespace), None without one."""
    for child in await node.get_children():
        if (await child.read_browse_name()).Name == name:
            return child
    return None
