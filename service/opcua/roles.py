"""Who an OPC UA session is: the role of our access policy (``protocol.roles``, the one
policy of every front end) that its activated user carries.

Every session a client activates gets a ``CncUser`` from the server's user manager
(``security.RoleUserManager``: anonymous on loopback as ``[opcua] loopback_role``, a user
name token as the role it names); the service's own internal session keeps asyncua's
plain ``User`` (``role_of`` is None: not a client).
"""

from __future__ import annotations

from dataclasses import dataclass

from asyncua.crypto.permission_rules import User, UserRole

from cnc_objects.protocol.roles import Role

#: asyncua's own role of a user of ours. asyncua lets only its Admin write attributes
#: through its default checks; our writes of bound variables decide by ``cnc_role``.
ASYNCUA_ROLE = {Role.MONITOR: UserRole.User, Role.OPERATOR: UserRole.User,
                Role.ADMIN: UserRole.User}


@dataclass
class CncUser(User):  # type: ignore[misc]  # asyncua is Any to mypy (pyproject)
    """An asyncua user that carries the role our access policy gives it."""

    cnc_role: Role = Role.MONITOR


def role_of(user: User | None) -> Role | None:
    """The role of a session whose user is ``user``; None for the server's own session."""
    return user.cnc_role if isinstance(user, CncUser) else None


def cnc_user(role: Role, name: str | None = None) -> CncUser:
    """The user of a session of ``role``."""
    return CncUser(role=ASYNCUA_ROLE[role], name=name, cnc_role=role)
