"""Browser sessions kept by the server, and the CSRF token that every write must carry.

The cookie holds only a random session id (256 bits); what it stands for lives in the
server's ``SessionStore``: the role, the CSRF token, when it began, and the password hash
with which it signed in. So a session can be ended at once, whatever the browser keeps:

- sign-out removes it;
- a changed or removed password of its role ends it at its next request, and its open
  WebSockets within a second (the hash it signed in with is no longer the role's:
  ``access.py``);
- it ends by itself ``SESSION_MAX_AGE_S`` after sign-in, and a restart of cnc-web ends all.

The page reads the CSRF token from ``GET /api/session`` and sends it in the
``X-CSRF-Token`` header of every write; a write whose header does not match its session's
token is refused (a page of another site can make the browser send the cookie, not read
the token).
"""

from __future__ import annotations

import hmac
import secrets
import time
from collections import OrderedDict
from dataclasses import dataclass

from .users import WebRole

COOKIE_NAME = "cnc_web_session"
CSRF_HEADER = "X-CSRF-Token"
SESSION_MAX_AGE_S = 12 * 3600  # one shift
MAX_SESSIONS = 1000  # sessions held at once; a new one beyond ends the oldest
SESSION_ID_BYTES = 32


@dataclass(frozen=True, slots=True)
class Session:
    """A signed-in browser: its role, its CSRF token, and what it signed in with."""

    role: WebRole
    csrf: str
    started_s: float  # time.monotonic() at sign-in
    password_hash: str | None  # the role's hash at sign-in; None: no sign-in (open server)


class SessionStore:
    """The live sessions by id, oldest first."""

    def __init__(self, max_sessions: int = MAX_SESSIONS,
                 max_age_s: float = SESSION_MAX_AGE_S) -> None:
        self._sessions: OrderedDict[str, Session] = OrderedDict()
        self.max_sessions = max_sessions
        self.max_age_s = max_age_s

    def __len__(self) -> int:
        return len(self._sessions)

    def issue(self, role: WebRole, password_hash: str | None) -> tuple[Session, str]:
        """A new session of ``role`` and its id (the cookie's value)."""
        session = Session(role, secrets.token_urlsafe(24), time.monotonic(), password_hash)
        session_id = secrets.token_urlsafe(SESSION_ID_BYTES)
        self._sessions[session_id] = session
        while len(self._sessions) > self.max_sessions:
            self._sessions.popitem(last=False)
        return session, session_id

    def get(self, session_id: str | None) -> Session | None:
        """The live session of ``session_id``; None when unknown, ended or too old."""
        if not session_id:
            return None
        session = self._sessions.get(session_id)
        if session is not None and time.monotonic() - session.started_s > self.max_age_s:
            del self._sessions[session_id]
            return None
        return session

    def items(self) -> list[tuple[str, Session]]:
        """Every session with its id, oldest first."""
        return list(self._sessions.items())

    def end(self, session_id: str | None) -> bool:
        """End the session ``session_id`` (sign-out); False when there was none."""
        return self._sessions.pop(session_id or "", None) is not None


def csrf_matches(session: Session, header: str | None) -> bool:
    """True when the request's CSRF header is the session's token (constant time)."""
    return header is not None and hmac.compare_digest(session.csrf, header)
