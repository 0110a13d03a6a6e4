"""Who may do what in cnc-web: sign-in, the session of each request, role checks.

Two ways to run:
- with a users file (``cnc web-users set ROLE``): every browser signs in as a role;
- without one (``open_role``): only on loopback, and every browser of this machine gets
  the open role's session at once, as the service trusts loopback peers without keys
  (``LOOPBACK_ROLE``: admin).

Each request needs the role the service would ask of the same request, taken from the
service's own table (``protocol/roles.py``): reads a monitor, writes and commands an
operator (``WRITE_ROLE``), the program store an admin (``STORE_ROLE``). Every request that
changes something also needs the session's CSRF token. A refusal is an HTTP error whose
JSON ``error`` is a sentence in the service's words (``ADS 0x704 INVALIDACCESS: role
monitor may not ...``), shown as is on the page.

Sessions live in the server (``sessions.py``): each request looks its cookie up, and a
session whose role's password changed or was removed since it signed in ends there.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
from collections.abc import Awaitable, Callable, Iterator
from dataclasses import dataclass, field

from aiohttp import web

from cnc_objects.protocol.constants import PROGRAM_STORE_GROUP, AdsCommand, CncPort
from cnc_objects.protocol.roles import COMMAND_ROLES, LOOPBACK_ROLE, role_to_write, roles_that_may

from .sessions import COOKIE_NAME, CSRF_HEADER, SESSION_MAX_AGE_S, Session, SessionStore, csrf_matches
from .signin import SignInGate
from .users import UsersFile, WebRole, WebUsers

log = logging.getLogger(__name__)

Handler = Callable[[web.Request], Awaitable[web.StreamResponse]]
SWEEP_S = 1.0  # how often open WebSockets of ended sessions are looked for
#: What a web request needs, as the service decides it for the requests cnc-web makes.
WRITE_ROLE = COMMAND_ROLES[AdsCommand.WRITE_CONTROL]  # objects, commands, MDI: operator
STORE_ROLE = role_to_write(CncPort.COM, PROGRAM_STORE_GROUP)  # upload programs: admin

ACCESS_KEY: web.AppKey[Access] = web.AppKey("access")
SESSION_KEY = "cnc_web_session"  # the request's Session, set by the middleware


def refusal(status: int, message: str,
            headers: dict[str, str] | None = None) -> web.HTTPException:
    """An HTTP error whose JSON body ``{"error": message}`` the page shows on its message
    line."""
    kind = _BY_STATUS.get(status, web.HTTPBadRequest)
    return kind(text=json.dumps({"error": message}), content_type="application/json",
                headers=headers)


_BY_STATUS: dict[int, type[web.HTTPException]] = {
    400: web.HTTPBadRequest, 401: web.HTTPUnauthorized, 403: web.HTTPForbidden,
    404: web.HTTPNotFound, 409: web.HTTPConflict, 421: web.HTTPMisdirectedRequest,
    429: web.HTTPTooManyRequests, 502: web.HTTPBadGateway, 504: web.HTTPGatewayTimeout,
}


@dataclass
class Access:
    """The sign-in rules of one cnc-web server, and its live sessions."""

    users_file: UsersFile | None  # None: no sign-in, everyone (on loopback) gets ``open_role``
    open_role: WebRole = LOOPBACK_ROLE
    sessions: SessionStore = field(default_factory=SessionStore)
    gate: SignInGate = field(default_factory=SignInGate)
    # The connections of each session's requests under way (its WebSockets above all):
    # closed when the session ends, so an open page stops receiving at once too.
    _running: dict[str, set[asyncio.BaseTransport]] = field(default_factory=dict)

    @property
    def sign_in_required(self) -> bool:
        """True when browsers must sign in."""
        return self.users_file is not None

    @property
    def users(self) -> WebUsers | None:
        """The users file as it is now (read again when it changed); None without one."""
        return self.users_file.current() if self.users_file is not None else None

    def session_of(self, request: web.Request) -> Session | None:
        """The live session the request's cookie names, if any. A session whose role's
        password changed or was removed since it signed in is ended here."""
        session_id = request.cookies.get(COOKIE_NAME)
        session = self.sessions.get(session_id)
        users = self.users
        if session is not None and users is not None and _outdated(session, users):
            self.end(session_id)
            return None
        return session

    def end(self, session_id: str | None, keep: asyncio.BaseTransport | None = None) -> bool:
        """End the session ``session_id``: in the store, and its requests under way (but
        the one on ``keep``) lose their connection. False when there was no session."""
        for transport in self._running.pop(session_id or "", set()) - {keep}:
            transport.close()
        return self.sessions.end(session_id)

    def sweep(self) -> int:
        """End every session whose role's password changed or was removed (the users
        file is read again when it changed); how many ended. Requests find such a session
        ended anyway; the sweep reaches the WebSockets, which make no requests."""
        users = self.users
        if users is None:
            return 0
        ended = [i for i, s in self.sessions.items() if _outdated(s, users)]
        for session_id in ended:
            self.end(session_id)
        return len(ended)

    @contextlib.contextmanager
    def running(self, session_id: str, transport: asyncio.BaseTransport | None) -> Iterator[None]:
        """While a request of ``session_id`` runs on ``transport`` (see ``end``)."""
        if transport is None:
            yield
            return
        self._running.setdefault(session_id, set()).add(transport)
        try:
            yield
        finally:
            transports = self._running.get(session_id)
            if transports is not None:
                transports.discard(transport)
                if not transports:
                    del self._running[session_id]

    def start_session(self, response: web.StreamResponse, role: WebRole,
                      password_hash: str | None) -> Session:
        """A new session of ``role`` (signed in with ``password_hash``), its cookie set
        on ``response``."""
        session, session_id = self.sessions.issue(role, password_hash)
        set_session_cookie(response, session_id)
        return session

    def end_session(self, request: web.Request, response: web.StreamResponse) -> bool:
        """Sign-out: the request's session ends in the server, its cookie is dropped."""
        response.del_cookie(COOKIE_NAME, path="/")
        return self.end(request.cookies.get(COOKIE_NAME), keep=request.transport)


def _outdated(session: Session, users: WebUsers) -> bool:
    """True when ``session``'s role no longer has the password it signed in with."""
    return session.password_hash is not None and \
        users.hashes.get(session.role) != session.password_hash


def set_session_cookie(response: web.StreamResponse, session_id: str) -> None:
    """Set the session cookie (not readable by scripts, never sent cross-site)."""
    response.set_cookie(COOKIE_NAME, session_id, max_age=SESSION_MAX_AGE_S, httponly=True,
                        samesite="Strict", path="/")


def current_session(request: web.Request) -> Session:
    """The session the middleware found for ``request``."""
    session: Session = request[SESSION_KEY]
    return session


def require_write(request: web.Request, what: str, needed: WebRole = WRITE_ROLE,
                  token: str | None = None) -> Session:
    """The request's session when its role covers ``needed`` (``what``: the request, for
    the refusal); else the refusal is raised: 403 with the service's sentence, or a CSRF
    mismatch. ``token``: the CSRF token when it cannot come as a header (a WebSocket's
    handshake carries it in its query)."""
    session = current_session(request)
    if not session.role.may(needed):
        raise refusal(403, f"ADS 0x704 INVALIDACCESS: role {session.role.label} may not {what}; "
                           f"{roles_that_may(needed)} may")
    if not csrf_matches(session, token if token is not None else request.headers.get(CSRF_HEADER)):
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
    if session is None:
        if not (request.path == "/" or request.path.startswith(_OPEN_PREFIXES)):
            raise refusal(401, "not signed in (sign in with a role's password)")
        return await handler(request)
    request[SESSION_KEY] = session
    with access.running(request.cookies[COOKIE_NAME], request.transport):
        return await handler(request)


async def sweep_sessions(access: Access, interval_s: float = SWEEP_S) -> None:
    """``access.sweep()`` every ``interval_s`` (a task of the application's life)."""
    while True:
        await asyncio.sleep(interval_s)
        ended = access.sweep()
        if ended:
            log.info("%d session(s) ended: their role's password changed or was removed", ended)
