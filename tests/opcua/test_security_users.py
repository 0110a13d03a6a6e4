"""User name tokens of the OPC UA front end: the user name is a role, its password the web
users file's (``cnc web-users set ROLE``); ``role_of`` gives the session's role
(service/opcua/security.py, docs/opcua.md "Security")."""

from __future__ import annotations

from pathlib import Path

import pytest
from asyncua.client.client import Client
from asyncua.crypto.permission_rules import User, UserRole
from asyncua.server.server import Server
from asyncua.ua.status_codes import StatusCodes
from asyncua.ua.uaerrors import UaStatusCodeError
from pydantic import ValidationError

from cnc_objects.protocol.role_passwords import RolePasswords
from cnc_objects.protocol.roles import Role
from cnc_objects.service.opcua.security import (
    FAILED_CHECK_PAUSE_S,
    OpcUaSecurityError,
    RoleUserManager,
    SessionUser,
    apply_security,
    role_of,
)
from cnc_objects.service.opcua.security_config import OpcUaSecurity
from tests.support.cli import cnc_process
from tests.support.opcua_security import (
    ANSWER,
    PASSWORDS,
    ClientIdentity,
    secure_client,
    secured_server,
)


@pytest.fixture(scope="module")
def settings(certificate_dir: Path, users_file: Path) -> OpcUaSecurity:
    return OpcUaSecurity(certificate_dir=str(certificate_dir), users_file=str(users_file))


async def test_each_role_signs_in_with_its_password(
    settings: OpcUaSecurity, certificate_dir: Path, trusted: ClientIdentity,
) -> None:
    async with secured_server(settings) as server:
        for role in Role:
            client = await secure_client(server.url, trusted, certificate_dir, user=role)
            async with client:
                assert await client.get_node(server.answer.nodeid).read_value() == ANSWER
        assert server.roles_read == list(Role)


@pytest.mark.parametrize(("user", "password"), [
    ("operator", PASSWORDS[Role.ADMIN]),  # another role's password
    ("operator", ""),
    ("root", PASSWORDS[Role.ADMIN]),  # not a role
], ids=["wrong-password", "no-password", "unknown-user"])
async def test_a_wrong_user_or_password_is_refused(
    settings: OpcUaSecurity, certificate_dir: Path, trusted: ClientIdentity,
    user: str, password: str,
) -> None:
    async with secured_server(settings) as server:
        client = await secure_client(server.url, trusted, certificate_dir)
        client.set_user(user)
        client.set_password(password)
        with pytest.raises(UaStatusCodeError) as refused:
            await client.connect()
        assert refused.value.code == StatusCodes.BadUserAccessDenied
        assert server.roles_read == []


async def test_a_token_type_not_offered_is_rejected(
    settings: OpcUaSecurity, certificate_dir: Path, trusted: ClientIdentity,
) -> None:
    """Off loopback anonymous is not offered: asyncua rejects the token itself."""
    async with secured_server(settings, host="0.0.0.0") as server:
        client = await secure_client(server.url, trusted, certificate_dir)
        with pytest.raises(UaStatusCodeError) as refused:
            await client.connect()
        assert refused.value.code == StatusCodes.BadIdentityTokenRejected


async def test_the_users_file_is_the_one_cnc_web_users_writes(tmp_path: Path) -> None:
    users_file = tmp_path / "web-users.json"
    made = cnc_process("web-users", "set", "operator", "--file", str(users_file),
                       input=f"{PASSWORDS[Role.OPERATOR]}\n")
    assert made.returncode == 0, made.stderr
    async with secured_server(OpcUaSecurity(users_file=str(users_file))) as server:
        client = Client(server.url, timeout=10)  # policy None on loopback, a user name
        client.set_user("operator")
        client.set_password(PASSWORDS[Role.OPERATOR])
        async with client:
            assert await client.get_node(server.answer.nodeid).read_value() == ANSWER
        assert server.roles_read == [Role.OPERATOR]


async def test_a_users_file_that_is_not_one_is_refused_at_start(
    tmp_path: Path, certificate_dir: Path,
) -> None:
    server = Server()
    await server.init()
    for text, problem in [(None, "cannot read the users file"),
                          ('{"version": 1, "roles": {"root": "x"}}', "unknown role 'root'")]:
        path = tmp_path / "users.json"
        if text is not None:
            path.write_text(text, encoding="utf-8")
        with pytest.raises(OpcUaSecurityError, match=problem):
            await apply_security(server, OpcUaSecurity(users_file=str(path)), "127.0.0.1")
    with pytest.raises(OpcUaSecurityError, match="nobody could sign in"):
        await apply_security(server, OpcUaSecurity(certificate_dir=str(certificate_dir)),
                             "0.0.0.0")


def test_after_a_wrong_password_no_password_is_checked_for_a_pause() -> None:
    """asyncua asks the user manager synchronously, on the event loop that serves the
    other front ends too: a guess costs an Argon2 check (some 100 ms), and after one the
    next checks wait ``FAILED_CHECK_PAUSE_S`` (refused unchecked)."""
    passwords = RolePasswords()
    passwords.set_password(Role.OPERATOR, "right")
    now_s = [100.0]
    manager = RoleUserManager(passwords, None, None, clock=lambda: now_s[0])
    iserver = Server().iserver
    assert manager.get_user(iserver, "operator", "wrong") is None
    now_s[0] += FAILED_CHECK_PAUSE_S / 2
    assert manager.get_user(iserver, "operator", "right") is None  # within the pause
    now_s[0] += FAILED_CHECK_PAUSE_S
    user = manager.get_user(iserver, "operator", "right")
    assert isinstance(user, SessionUser) and role_of(user) is Role.OPERATOR
    assert manager.get_user(iserver, None) is None  # anonymous: not offered here


def test_role_of_a_user_that_is_not_ours_is_the_least() -> None:
    assert role_of(SessionUser(role=UserRole.User, cnc_role=Role.ADMIN)) is Role.ADMIN
    assert role_of(User(role=UserRole.User)) is Role.MONITOR
    assert role_of(User(role=UserRole.Anonymous)) is Role.MONITOR
    assert role_of(None) is Role.MONITOR
    server = Server()  # the server's own (internal) session writes as the server: admin
    assert role_of(server.iserver.isession) is Role.ADMIN


def test_the_opcua_keys_refuse_what_they_do_not_know() -> None:
    with pytest.raises(ValidationError, match="loopback_role"):
        OpcUaSecurity.model_validate({"loopback_role": "root"})
    with pytest.raises(ValidationError, match="user_file"):
        OpcUaSecurity.model_validate({"user_file": "web-users.json"})  # users_file misspelt
