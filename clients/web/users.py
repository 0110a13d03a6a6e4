"""The web users file: one password per role, stored as an Argon2 hash (argon2-cffi).

Browser users sign in as a role (``monitor``, ``operator``, ``admin``: the service's
roles, docs/security.md) with that role's password. The file is JSON,
``{"version": 1, "roles": {"operator": "$argon2id$..."}}``, written by
``cnc web-users set ROLE`` with mode 0600; it never holds a password in clear.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from enum import IntEnum
from pathlib import Path

from argon2 import PasswordHasher
from argon2.exceptions import InvalidHashError, VerificationError

DEFAULT_USERS_FILE = Path("cnc-data/web-users.json")  # beside make run's program store
FILE_VERSION = 1


class WebRole(IntEnum):
    """A browser user's role; each may what the ones below may (as the service's roles)."""

    MONITOR = 1
    OPERATOR = 2
    ADMIN = 3

    @classmethod
    def parse(cls, name: str) -> WebRole:
        """The role called ``name`` (any case); ``ValueError`` naming the roles."""
        try:
            return cls[name.upper()]
        except KeyError:
            raise ValueError(
                f"unknown role {name!r}: one of {', '.join(r.name.lower() for r in cls)}"
            ) from None

    @property
    def label(self) -> str:
        """The role's name as the service writes it (``operator``)."""
        return self.name.lower()


_HASHER = PasswordHasher()


@dataclass
class WebUsers:
    """The password hash of each role that may sign in."""

    hashes: dict[WebRole, str] = field(default_factory=dict)

    def set_password(self, role: WebRole, password: str) -> None:
        """Store ``role``'s new password (hashed); ``ValueError`` when it is empty."""
        if not password:
            raise ValueError("the password is empty")
        self.hashes[role] = _HASHER.hash(password)

    def remove(self, role: WebRole) -> bool:
        """Forget ``role``'s password (it can no longer sign in); False when it had none."""
        return self.hashes.pop(role, None) is not None

    def verify(self, role: WebRole, password: str) -> bool:
        """True when ``password`` is ``role``'s password."""
        stored = self.hashes.get(role)
        if stored is None:
            return False
        try:
            return _HASHER.verify(stored, password)
        except (VerificationError, InvalidHashError):
            return False

    @property
    def roles(self) -> list[WebRole]:
        """The roles that can sign in, lowest first."""
        return sorted(self.hashes)


def load_users(path: Path) -> WebUsers:
    """The users of ``path``; ``ValueError`` with the file's name when it is not one."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        roles = data["roles"]
        if data.get("version") != FILE_VERSION or not isinstance(roles, dict):
            raise ValueError(f"version {data.get('version')!r}, expected {FILE_VERSION}")
        return WebUsers({WebRole.parse(name): str(h) for name, h in roles.items()})
    except (OSError, json.JSONDecodeError, KeyError, TypeError, ValueError) as exc:
        raise ValueError(f"{path} is not a web users file: {exc}") from None


def save_users(path: Path, users: WebUsers) -> None:
    """Write ``users`` to ``path`` (mode 0600: the hashes are secret enough)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    data = {"version": FILE_VERSION, "roles": {r.label: h for r, h in sorted(users.hashes.items())}}
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "w", encoding="utf-8") as out:
        json.dump(data, out, indent=2)
        out.write("\n")
