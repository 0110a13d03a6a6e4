"""Who may talk to the OPC UA front end, and as which role (docs/opcua.md, "Security").

The server calls ``apply_security`` once, after ``Server.init()`` and before
``Server.start()``; afterwards ``role_of(user)`` tells the role (monitor, operator,
admin: ``protocol/roles.py``) of the session that sent a request. What it sets up:

- Secure channels. SecurityPolicy None is offered only when the server listens on a
  loopback host, as the ZeroMQ and ADS front ends serve only loopback without keys or
  routes. With ``[opcua] certificate_dir`` (``cnc opcua-cert`` makes it) Basic256Sha256
  Sign and SignAndEncrypt are offered too; a server on any other host needs them. asyncua
  opens a None channel anyway (for GetEndpoints) and creates sessions on it: off
  loopback the user manager activates none there.
- Client certificates. Only a certificate in ``trusted_clients_dir`` (default
  ``certificate_dir/trusted``) gets a session: asyncua's ``CertificateValidator`` with
  its ``TrustStore`` checks the one a client names in CreateSession (time, application
  URI, key usage, trust; ``BadCertificateUntrusted`` and kin), and the user manager
  checks the certificate that secures the channel again at ActivateSession, because
  asyncua does not compare the two (a client could name someone else's certificate).
- Users. A user name token names a role; its password is that role's in the web users
  file (``cnc web-users set ROLE``, ``protocol/role_passwords.py``). Anonymous sessions
  are allowed on a loopback host only, with ``[opcua] loopback_role`` (default admin,
  monitor when the server has a certificate). A wrong password or a user name that is
  not a role with a password: ``BadUserAccessDenied``, as asyncua answers a refused user;
  a token type not offered (anonymous off loopback): ``BadIdentityTokenRejected``.

Certificates, trust list and passwords are read at start: restart to apply a change.
"""

from __future__ import annotations

import logging
import stat
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from asyncua import ua
from asyncua.crypto.permission_rules import User, UserRole
from asyncua.crypto.truststore import TrustStore
from asyncua.crypto.validator import CertificateValidator, CertificateValidatorOptions
from asyncua.server.internal_server import InternalServer
from asyncua.server.internal_session import InternalSession
from asyncua.server.server import Server
from asyncua.server.user_managers import UserManager
from cryptography import x509

from cnc_objects.protocol.opcua_files import CERTIFICATE_FILE, PRIVATE_KEY_FILE, TRUSTED_DIR
from cnc_objects.protocol.role_passwords import RolePasswords, parse_role_passwords
from cnc_objects.protocol.roles import LOOPBACK_ROLE, Role

from ..log_throttle import ThrottledWarning
from ..security import host_is_loopback
from .roles import CncUser, cnc_user
from .roles import role_of as client_role_of
from .security_config import OpcUaSecurity

log = logging.getLogger(__name__)

#: After a wrong password no password is checked for this long: asyncua asks its user
#: manager synchronously, so each Argon2 check (some 100 ms) stops the event loop that
#: serves ZeroMQ and ADS too; guessing may cost the other front ends at most this share.
FAILED_CHECK_PAUSE_S = 1.0
#: Everything asyncua's validator checks of a client certificate in CreateSession.
CLIENT_CERTIFICATE_CHECKS = (CertificateValidatorOptions.TRUSTED_VALIDATION
                             | CertificateValidatorOptions.PEER_CLIENT)
SECURED_POLICIES = (ua.SecurityPolicyType.Basic256Sha256_SignAndEncrypt,
                    ua.SecurityPolicyType.Basic256Sha256_Sign)


class OpcUaSecurityError(ValueError):
    """The security settings cannot be served; the message says which file or key and why."""


#: asyncua's user of a session, with the service's role (``roles.CncUser``): asyncua's own
#: role is ``UserRole.User`` for every one of ours (read, write, call, subscribe; never add
#: or delete nodes, ``SimpleRoleRuleset``); what a write or call needs is ours to say.
SessionUser = CncUser


def role_of(who: InternalSession | User | None) -> Role:
    """The service's role of a session or of its user. The server's own session (asyncua's
    internal admin) is admin; a user this module did not make is monitor, the least."""
    user = who.user if isinstance(who, InternalSession) else who
    role = client_role_of(user)
    if role is not None:
        return role
    if user is not None and user.role is UserRole.Admin:
        return Role.ADMIN  # asyncua's internal session: the server itself
    return Role.MONITOR


class RoleUserManager(UserManager):  # type: ignore[misc]  # asyncua is Any to mypy (pyproject)
    """asyncua's user manager: the session's user from the channel's certificate and the
    identity token (called at ActivateSession; None: ``BadUserAccessDenied``)."""

    def __init__(self, passwords: RolePasswords | None, anonymous_role: Role | None,
                 trust: TrustStore | None, secured_only: bool = False,
                 clock: Callable[[], float] = time.monotonic) -> None:
        """``secured_only``: no session on a SecurityPolicy None channel (off loopback)."""
        self._passwords = passwords
        self._anonymous_role = anonymous_role
        self._trust = trust
        self._secured_only = secured_only
        self._clock = clock
        self._paused_until_s = 0.0
        # a client can cause refusals at will: the first is logged, then one line a while
        self._refusals = ThrottledWarning(log, "OPC UA session refused")

    def _refuse(self, why: str) -> None:
        self._refusals.note(why)

    def get_user(self, iserver: InternalServer, username: str | None = None,
                 password: str | None = None, certificate: Any = None) -> User | None:
        """The user of a session (asyncua's ``UserManager.get_user``); ``certificate`` is
        the DER certificate of the secure channel (None on SecurityPolicy None)."""
        if not certificate:  # None, b"": a SecurityPolicy None channel
            if self._secured_only:
                # asyncua opens a None channel on any server (GetEndpoints needs one) and
                # creates sessions on it; off loopback none is activated there
                self._refuse("its channel has SecurityPolicy None, served on "
                             "loopback only")
                return None
        elif not self._trusted(bytes(certificate)):
            return None
        if username is None:
            if self._anonymous_role is None:
                self._refuse("anonymous is served on loopback only")
                return None
            return cnc_user(self._anonymous_role, "anonymous")
        role = self._checked_role(username, password or "")
        if role is None:
            return None
        log.info("OPC UA session of user %s (role %s)", username, role.label)
        return cnc_user(role, role.label)

    def _checked_role(self, username: str, password: str) -> Role | None:
        """The role ``username`` names when ``password`` is its password, else None."""
        passwords = self._passwords
        try:
            role = Role.parse(username) if username.strip() else None
        except ValueError:
            role = None
        if passwords is None or role is None or role not in passwords.hashes:
            self._refuse(f"user {username[:64]!r}: the user name must be a role with a "
                         "password (cnc web-users set ROLE)")
            return None
        if self._clock() < self._paused_until_s:
            self._refuse(f"user {role.label} unchecked: a wrong password came less "
                         f"than {FAILED_CHECK_PAUSE_S:g} s ago")
            return None
        if not passwords.verify(role, password):
            self._paused_until_s = self._clock() + FAILED_CHECK_PAUSE_S
            self._refuse(f"user {role.label}: wrong password")
            return None
        return role

    def _trusted(self, der: bytes) -> bool:
        try:
            certificate = x509.load_der_x509_certificate(der)
        except ValueError:
            self._refuse("its channel certificate does not parse")
            return False
        if self._trust is None or not self._trust.validate(certificate):
            self._refuse(f"its certificate {certificate.subject.rfc4514_string()} is not "
                         "trusted")
            return False
        return True


async def apply_security(server: Server, settings: OpcUaSecurity, host: str) -> str:
    """Set ``server``'s security policies, certificate, trust list and user manager from
    ``settings`` for a server listening on ``host``. Call after ``server.init()`` (it sets
    the application URI, the certificate's) and before ``server.start()``. Returns what is
    served, in words for the start-up log; ``OpcUaSecurityError`` says what cannot be."""
    loopback = host_is_loopback(host)
    certificate_dir = _path(settings.certificate_dir)
    if certificate_dir is None and not loopback:
        raise OpcUaSecurityError(
            f"OPC UA on {host} is not a loopback address and [opcua] has no certificate_dir: "
            "SecurityPolicy None is served on loopback only; make a certificate (cnc "
            "opcua-cert --dir DIR), or listen on 127.0.0.1")
    trust: TrustStore | None = None
    if certificate_dir is not None:
        await _load_certificate(server, certificate_dir)
        trusted = _path(settings.trusted_clients_dir) or certificate_dir / TRUSTED_DIR
        trust = await _trust_store(trusted)
        server.set_certificate_validator(CertificateValidator(CLIENT_CERTIFICATE_CHECKS, trust))
    passwords = _passwords(_path(settings.users_file))
    anonymous_role: Role | None = None
    if loopback:
        default_role = Role.MONITOR if certificate_dir is not None else LOOPBACK_ROLE
        anonymous_role = (Role.parse(settings.loopback_role) if settings.loopback_role
                          else default_role)
    elif passwords is None:
        raise OpcUaSecurityError(
            f"OPC UA on {host}: anonymous sessions are served on loopback only and [opcua] "
            "has no users_file: nobody could sign in (cnc web-users set ROLE)")
    policies = ([ua.SecurityPolicyType.NoSecurity] if loopback else []) + (
        list(SECURED_POLICIES) if certificate_dir is not None else [])
    # asyncua's default permission ruleset stays: our users are its UserRole.User (read,
    # write, call, subscribe; no adding or deleting nodes)
    server.set_security_policy(policies)
    tokens: list[type] = [ua.AnonymousIdentityToken] if anonymous_role is not None else []
    tokens += [ua.UserNameIdentityToken] if passwords is not None else []
    server.set_identity_tokens(tokens)
    server.iserver.set_user_manager(
        RoleUserManager(passwords, anonymous_role, trust, secured_only=not loopback))
    return (f"security policies {', '.join(p.name for p in policies)}; anonymous "
            f"{'as ' + anonymous_role.label if anonymous_role else 'refused'}; user names "
            f"{', '.join(r.label for r in passwords.roles) if passwords else 'none'}")


def _path(text: str | None) -> Path | None:
    return Path(text).expanduser() if text else None


async def _load_certificate(server: Server, directory: Path) -> None:
    """The application certificate and key of ``directory``; the server's application
    URI becomes the certificate's (OPC UA clients compare the two)."""
    certificate_file, key_file = directory / CERTIFICATE_FILE, directory / PRIVATE_KEY_FILE
    for path in (certificate_file, key_file):
        if not path.is_file():
            raise OpcUaSecurityError(f"{path} does not exist (make it: cnc opcua-cert --dir "
                                     f"{directory})")
    try:
        certificate = x509.load_der_x509_certificate(certificate_file.read_bytes())
        uris = certificate.extensions.get_extension_for_class(
            x509.SubjectAlternativeName).value.get_values_for_type(x509.UniformResourceIdentifier)
        await server.load_certificate(certificate_file)
        await server.load_private_key(key_file)
    except (OSError, ValueError, TypeError, x509.ExtensionNotFound) as exc:
        raise OpcUaSecurityError(f"cannot use the certificate in {directory}: {exc}") from None
    if not uris:
        raise OpcUaSecurityError(f"{certificate_file} names no application URI in its "
                                 "subjectAltName (make it with cnc opcua-cert)")
    if key_file.stat().st_mode & (stat.S_IRGRP | stat.S_IROTH):
        log.warning("%s can be read by other users; chmod 600 it", key_file)
    await server.set_application_uri(uris[0])


async def _trust_store(directory: Path) -> TrustStore:
    """asyncua's trust store of the certificates in ``directory``. Without any it stays
    unloaded (asyncua cannot load an empty one), which trusts no certificate."""
    if not directory.is_dir():
        raise OpcUaSecurityError(f"the trusted clients directory {directory} does not exist")
    trust = TrustStore([directory], [])
    if not any(p.suffix.lower() in (".der", ".pem") for p in directory.iterdir()):
        log.warning("no trusted OPC UA client certificates (*.der, *.pem) in %s: every "
                    "client with a certificate is refused", directory)
        return trust
    try:
        await trust.load()
    except (OSError, ValueError) as exc:
        raise OpcUaSecurityError(f"a certificate in {directory} cannot be read: {exc}") from None
    return trust


def _passwords(path: Path | None) -> RolePasswords | None:
    if path is None:
        return None
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise OpcUaSecurityError(f"cannot read the users file {path}: {exc}") from None
    try:
        passwords = parse_role_passwords(text, str(path))
    except ValueError as exc:
        raise OpcUaSecurityError(str(exc)) from None
    if not passwords.roles:
        log.warning("%s has no password: no OPC UA user name is accepted", path)
    return passwords
