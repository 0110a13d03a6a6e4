"""The Read and Write services of the OPC UA front end. A Read fetches the objects of the
bound variables it reads in one round trip to the service. A client's write of a bound variable goes
to the CNC objects (``binding.VariableBinder.write``); every other node is read-only to
clients (BadNotWritable), whatever its AccessLevel in the nodesets says. The server's
own writes (its internal session) take asyncua's path."""

from __future__ import annotations

from asyncua import ua
from asyncua.crypto.permission_rules import User, UserRole
from asyncua.server.address_space import AddressSpace, AttributeService

from .binding import VariableBinder
from .roles import role_of

_VALUE = ua.AttributeIds.Value
_SERVER_USER = User(role=UserRole.Admin)  # asyncua's default: the server's own writes


class BoundAttributes(AttributeService):  # type: ignore[misc]  # asyncua is Any to mypy
    """asyncua's attribute service with the writes of clients decided by ``binder``."""

    def __init__(self, aspace: AddressSpace, binder: VariableBinder) -> None:
        super().__init__(aspace)
        self.binder = binder

    def read(self, params: ua.ReadParameters) -> list[ua.DataValue]:
        """asyncua's Read, the objects of every bound Value it reads fetched from the
        service first, all in one round trip (``LinkedBackend.prefetched``)."""
        variables = self.binder.variables
        entries = [entry for item in params.NodesToRead
                   if item.AttributeId == _VALUE and item.NodeId in variables
                   for entry in variables[item.NodeId].entries]
        with self.binder.backend.prefetched(entries):
            return super().read(params)  # type: ignore[no-any-return]

    async def write(self, params: ua.WriteParameters, user: User = _SERVER_USER
                    ) -> list[ua.StatusCode]:
        """One status per item; a client's items one after the other, in order."""
        if role_of(user) is None:  # the server itself
            return await super().write(params, user)  # type: ignore[no-any-return]
        results = []
        for item in params.NodesToWrite:
            if item.AttributeId == ua.AttributeIds.Value and item.NodeId in self.binder.variables:
                results.append(await self.binder.write(item.NodeId, item.Value, user))
            elif item.NodeId not in self._aspace:
                results.append(ua.StatusCode(ua.StatusCodes.BadNodeIdUnknown))
            else:
                results.append(ua.StatusCode(ua.StatusCodes.BadNotWritable))
        return results
