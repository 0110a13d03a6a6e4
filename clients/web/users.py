"""The web users file: one password per role, stored as an Argon2 hash (argon2-cffi).

Browser users sign in as a role (``monitor``, ``operator``, ``admin``: the service's
roles, ``protocol/roles.py``, docs/security.md) with that role's password. The file is
JSON, ``{"version": 1, "roles": {"operator": "$argon2id$..."}}``, written by
``cnc web-users set ROLE`` with mode 0600 (atomically: a reader never sees half a file);
it never holds a password in clear. ``UsersFile`` follows the file while cnc-web runs: a
changed or removed password applies to the next request (``access.py`` then ends that
role's sessions).
"""

from __future__ import annotations

import json
import logging
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from argon2 import PasswordHasher
from argon2.exceptions import InvalidHashError, VerificationError

from cnc_objects.protocol.roles import Role

log = logging.getLogger(__name__)

DEFAULT_USERS_FILE = Path("cnc-data/web-users.json")  # beside make run's program store
FILE_VERSION = 1


#: A browser user's role: the service's own roles (one table, ``protocol/roles.py``), so a
#: web role may exactly what the service lets a key or route of that role do.
WebRole = Role


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
    # A new file renamed over the old one: cnc-web, which reads the file while it runs,
    # sees the old users or the new ones, never a truncated file.
    fd, temporary = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)  # mode 0600
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as out:
            json.dump(data, out, indent=2)
            out.write("\n")
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


class UsersFile:
    """The users file of a running cnc-web, read again when it changes on disk.

    ``current()`` compares the file's identity (inode, size, modification time in ns) with
    the one read last: one ``stat`` per request. A file that is gone or no longer a users
    file leaves no role able to sign in (logged): cnc-web never falls back to serving
    without sign-in.
    """

    def __init__(self, path: Path) -> None:
        self.path = path
        self._users = load_users(path)  # ValueError at start: cnc-web refuses to run
        self._identity = self._stat()

    def _stat(self) -> tuple[int, int, int] | None:
        try:
            found = self.path.stat()
        except OSError:
            return None
        return (found.st_ino, found.st_size, found.st_mtime_ns)

    def current(self) -> WebUsers:
        """The users as the file holds them now."""
        identity = self._stat()
        if identity != self._identity:
            self._identity = identity
            try:
                self._users = load_users(self.path)
                log.info("%s changed: roles that may sign in: %s", self.path,
                         ", ".join(r.label for r in self._users.roles) or "none")
            except ValueError as exc:
                self._users = WebUsers()
                log.warning("%s; no role can sign in until it is a users file again", exc)
        return self._users
