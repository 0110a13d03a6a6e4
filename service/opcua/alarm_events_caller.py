"""Who calls an OPC UA method: asyncua hands a method's callback the object and the
arguments, not the session. The sessions of this server are ``CallingSession`` objects
that make their user known to the callbacks of a Call (``calling_user``), so that a
method decides by the caller's role as a write does (``roles.role_of``).
"""

from __future__ import annotations

from contextvars import ContextVar
from typing import Any

from asyncua import ua
from asyncua.crypto.permission_rules import User, UserRole
from asyncua.server.internal_server import InternalServer
from asyncua.server.internal_session import InternalSession

_CALLER: ContextVar[User | None] = ContextVar("opcua_caller", default=None)


class CallingSession(InternalSession):  # type: ignore[misc]  # asyncua is Any to mypy
    """asyncua's session whose Call tells the callbacks who calls."""

    async def call(self, params: list[ua.CallMethodRequest]) -> list[ua.CallMethodResult]:
        """asyncua's Call, with ``calling_user`` this session's user meanwhile."""
        token = _CALLER.set(self.user)
        try:
            return await super().call(params)  # type: ignore[no-any-return]
        finally:
            _CALLER.reset(token)


class CallingSessions:
    """``InternalServer.create_session`` that makes ``CallingSession`` objects."""

    def __init__(self, iserver: InternalServer) -> None:
        self.iserver = iserver

    def __call__(self, name: str, user: User = User(role=UserRole.Anonymous),  # noqa: B008
                 external: bool = False) -> CallingSession:
        iserver = self.iserver
        return CallingSession(iserver, iserver.aspace, iserver.subscription_service, name,
                              user=user, external=external)


def install(iserver: Any) -> None:
    """Make every session created from now on a ``CallingSession``."""
    if not isinstance(iserver.create_session, CallingSessions):
        iserver.create_session = CallingSessions(iserver)


def calling_user() -> User | None:
    """The user of the session whose Call runs now; None outside a client's Call (the
    server's own calls)."""
    return _CALLER.get()
