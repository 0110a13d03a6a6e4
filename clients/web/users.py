"""The web users file: one password per role, stored as an Argon2 hash (argon2-cffi).

Browser users sign in as a role (``monitor``, ``operator``, ``admin``: the service's
roles, ``protocol/roles.py``, docs/security.md) with that role's password. The file is
JSON, ``{"version": 1, "roles": {"operator": "$argon2id$..."}}``, written by
``cnc web-users set ROLE`` with mode 0600 (atomically: a reader never sees half a file);
it never holds a password in clear. ``UsersFile`` follows the file while cnc-web runs: a
changed or removed password applies to the next request (``access.py`` then ends that
role's sessions). The format and the password check are ``protocol/role_passwords.py``'s:
the service's OPC UA front end reads the same file (docs/opcua.md, "Security").
"""

from __future__ import annotations

import logging
import os
import tempfile
from pathlib import Path

from cnc_objects.protocol.role_passwords import (
    FILE_VERSION,
    RolePasswords,
    format_role_passwords,
    parse_role_passwords,
)
from cnc_objects.protocol.roles import Role

__all__ = ["DEFAULT_USERS_FILE", "FILE_VERSION", "UsersFile", "WebRole", "WebUsers",
           "load_users", "save_users"]

log = logging.getLogger(__name__)

DEFAULT_USERS_FILE = Path("cnc-data/web-users.json")  # beside make run's program store


#: A browser user's role: the service's own roles (one table, ``protocol/roles.py``), so a
#: web role may exactly what the service lets a key or route of that role do.
WebRole = Role

#: The password hash of each role that may sign in: the format is the protocol's
#: (``protocol/role_passwords.py``), which the service's OPC UA front end reads too.
WebUsers = RolePasswords


def load_users(path: Path) -> WebUsers:
    """The users of ``path``; ``ValueError`` with the file's name when it is not one."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path} is not a web users file: {exc}") from None
    return parse_role_passwords(text, str(path))


def save_users(path: Path, users: WebUsers) -> None:
    """Write ``users`` to ``path`` (mode 0600: the hashes are secret enough)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    # A new file renamed over the old one: cnc-web, which reads the file while it runs,
    # sees the old users or the new ones, never a truncated file.
    fd, temporary = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)  # mode 0600
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as out:
            out.write(format_role_passwords(users))
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
