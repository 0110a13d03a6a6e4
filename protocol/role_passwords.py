"""One password per role, as Argon2 hashes (argon2-cffi), and the text of its file.

A person signs in as a role (``monitor``, ``operator``, ``admin``: ``roles.py``) with that
role's password: in a browser to cnc-web, and as the user name of an OPC UA user token
(docs/opcua.md, "Security"). The file is JSON, ``{"version": 1, "roles": {"operator":
"$argon2id$..."}}``, written by ``cnc web-users set ROLE``; it never holds a password in
clear.

This module is the format alone, text in and text out, no files: the service (the OPC UA
front end) and the clients (``cnc web-users``, cnc-web) both read it, and the protocol is
the one layer both may import (docs/architecture.md). Reading, writing and following the
file are theirs (``clients/web/users.py``, ``service/opcua/security.py``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

from argon2 import PasswordHasher
from argon2.exceptions import InvalidHashError, VerificationError

from .roles import Role

FILE_VERSION = 1

_HASHER = PasswordHasher()


@dataclass
class RolePasswords:
    """The password hash of each role that may sign in."""

    hashes: dict[Role, str] = field(default_factory=dict)

    def set_password(self, role: Role, password: str) -> None:
        """Store ``role``'s new password (hashed); ``ValueError`` when it is empty."""
        if not password:
            raise ValueError("the password is empty")
        self.hashes[role] = _HASHER.hash(password)

    def remove(self, role: Role) -> bool:
        """Forget ``role``'s password (it can no longer sign in); False when it had none."""
        return self.hashes.pop(role, None) is not None

    def verify(self, role: Role, password: str) -> bool:
        """True when ``password`` is ``role``'s password. An Argon2id check costs some
        100 ms of CPU and 64 MiB on purpose: callers on an event loop mind it."""
        stored = self.hashes.get(role)
        if stored is None:
            return False
        try:
            return _HASHER.verify(stored, password)
        except (VerificationError, InvalidHashError):
            return False

    @property
    def roles(self) -> list[Role]:
        """The roles that can sign in, lowest first."""
        return sorted(self.hashes)


def parse_role_passwords(text: str, source: str) -> RolePasswords:
    """The passwords of a file's ``text``; ``ValueError`` naming ``source`` (the file)
    when it is not a role passwords file."""
    try:
        data = json.loads(text)
        roles = data["roles"]
        if data.get("version") != FILE_VERSION or not isinstance(roles, dict):
            raise ValueError(f"version {data.get('version')!r}, expected {FILE_VERSION}")
        return RolePasswords({Role.parse(name): str(h) for name, h in roles.items()})
    except (json.JSONDecodeError, KeyError, TypeError, ValueError, AttributeError) as exc:
        raise ValueError(f"{source} is not a web users file: {exc}") from None


def format_role_passwords(passwords: RolePasswords) -> str:
    """The file's text for ``passwords`` (JSON, roles lowest first, a final newline)."""
    data = {"version": FILE_VERSION,
            "roles": {r.label: h for r, h in sorted(passwords.hashes.items())}}
    return json.dumps(data, indent=2) + "\n"
