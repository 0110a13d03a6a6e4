"""Who may do what in cnc-web: sign-in, the session of each request, write checks.

Two ways to run:
- with a users file (``cnc web-users set ROLE``): every browser signs in as a role;
- without one (``open_role``): only on loopback, and every browser of this machine gets
  the open role's session at once, as the service trusts loopback peers without keys.

Every write needs the role ``operator`` (or more) and the session's CSRF token; a
refusal is an HTTP error whose JSON ``error`` is a sentence in the service's words
(``ADS 0x704 INVALIDACCESS: role monitor may not ...``), shown as is on the page.
"""

from __future__ import annotations

import json
from collections.abc import Awaitable, Callable
from dataclasses import dataclass

from aiohttp import web

from .sessions import COOKIE_NAME, CSRF_HEADER, SESSION_MAX_AGE_S, Session, SessionSigner, csrf_matches
from .users import WebRole, WebUsers

Handler = Callable[[web.Request], Awaitable[web.StreamResponse]]
WRITE_ROLE = WebRole.OPERATOR  # the service's rule: monitor reads, operator writes

ACCESS_KEY: web.AppKey[Access] = web.AppKey("access")
SESSION_KEY = "cnc_web_session"  # the request's Session, set by the middleware


def refusal(status: int, message: str) -> web.HTTPException:
    """An HTTP error whose JSON body ``{"error": message}`` the page shows on its message
    line."""
    kind = _BY_STATUS.get(status, web.HTTPBadRequest)
    return kind(text=json.dumps({"error": message}), content_type="application/json")


_BY_STATUS: dict[int, type[web.HTTPException]] = {
    400: web.HTTPBadRequest, 401: web.HTTPUnauthorized, 403: web.HTTPForbidden,
    404: web.HTTPNotFound, 409: web.HTTPConflict, 502: web.HTTPBadGateway,
    504: web.HTTPGatewayTimeout,
}


@dataclass
class Access:
    """The sign-in rules of one cnc-web server."""

    signer: SessionSigner
    users: WebUsers | None  # None: no sign-in, everyone (on loopback) gets ``open_role``
    open_role: WebRole = WebRole.OPERATOR

    @property
    def sign_in_required(self) -> bool:
        """True when browsers must sign in."""
        return self.users is not None

    def session_of(self, request: web.Request) -> Session | None:
        """The signed session the request's cookie carries, if any."""
        return self.signer.read(request.cookies.get(COOKIE_NAME))

    def start_session(self, response: web.StreamResponse, role: WebRole) -> Session:
        """A new session of ``role``, its cookie set on ``response``."""
        session, cookie = self.signer.issue(role)
        set_session_cookie(response, cookie)
        return session


def set_session_cookie(response: web.StreamResponse, cookie: str) -> None:
    """Set the signed session cookie (not readable by scripts, never sent cross-site)."""
    response.set_cookie(COOKIE_NAME, cookie, max_age=SESSION_MAX_AGE_S, httponly=True,
                        samesite="Strict", path="/")


def current_session(request: web.Request) -> Session:
    """The session the middleware found for ``request``."""
    session: Session = request[SESSION_KEY]
    return session


def require_write(request: web.Request, what: str) -> Session:
    """The request's session when it may write (``what``: the write, for the refusal);
    else the refusal is raised: 403 with the service's sentence, or a CSRF mismatch."""
    session = current_session(request)
    if session.role < WRITE_ROLE:
        raise refusal(403, f"ADS 0x704 INVALIDACCESS: role {session.role.label} may not {what}; "
                           "operator or admin may")
    if not csrf_matches(session, request.headers.get(CSRF_HEADER)):
        raise refusal(403, f"refused: {what} came without this session's CSRF token "
                           "(reload the page)")
    return session


# Paths that need no session: the pages themselves, and signing in.
_OPEN_PREFIXES = ("/static/", "/api/session", "/api/login", "/favicon.ico")


@web.middleware
async def session_middleware(request: web.Request, handler: Handler) -> web.StreamResponse:
    """Attach the request's session; refuse API calls and the WebSocket without one."""
    access = request.app[ACCESS_KEY]
    session = access.session_of(request)
    if session is not None:
        request[SESSION_KEY] = session
    elif not (request.path == "/" or request.path.startswith(_OPEN_PREFIXES)):
        raise refusal(401, "not signed in (sign in with a role's password)")
    return await handler(request)
