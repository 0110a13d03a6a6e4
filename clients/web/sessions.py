"""Browser sessions in signed cookies, and the CSRF token that every write must carry.

The cookie holds ``{"role": "operator", "csrf": "<random>"}`` signed with the server's
secret (itsdangerous, with a timestamp: a session ends after ``SESSION_MAX_AGE_S``). The
page reads the CSRF token from ``GET /api/session`` and sends it in the ``X-CSRF-Token``
header of every write; a write whose header does not match its cookie's token is refused
(a page of another site can make the browser send the cookie, not read the token).
"""

from __future__ import annotations

import hmac
import secrets
from dataclasses import dataclass

from itsdangerous import BadSignature, URLSafeTimedSerializer

from .users import WebRole

COOKIE_NAME = "cnc_web_session"
CSRF_HEADER = "X-CSRF-Token"
SESSION_MAX_AGE_S = 12 * 3600  # one shift


@dataclass(frozen=True, slots=True)
class Session:
    """A signed-in browser: its role and its CSRF token."""

    role: WebRole
    csrf: str


class SessionSigner:
    """Makes and reads the session cookie's value."""

    def __init__(self, secret: str | None = None) -> None:
        # A random secret per server start: restarting cnc-web signs everyone out.
        self._serializer = URLSafeTimedSerializer(secret or secrets.token_hex(32), "cnc-web")

    def issue(self, role: WebRole) -> tuple[Session, str]:
        """A new session of ``role`` and its cookie value."""
        session = Session(role, secrets.token_urlsafe(24))
        return session, self._serializer.dumps({"role": role.label, "csrf": session.csrf})

    def read(self, cookie: str | None) -> Session | None:
        """The session of ``cookie``; None when missing, forged, expired or malformed."""
        if not cookie:
            return None
        try:
            data = self._serializer.loads(cookie, max_age=SESSION_MAX_AGE_S)
            return Session(WebRole.parse(data["role"]), str(data["csrf"]))
        except (BadSignature, KeyError, TypeError, ValueError):
            return None


def csrf_matches(session: Session, header: str | None) -> bool:
    """True when the request's CSRF header is the session's token (constant time)."""
    return header is not None and hmac.compare_digest(session.csrf, header)
