"""Secure channels of the OPC UA front end: Basic256Sha256 with a trusted client
certificate, refusals of untrusted ones, SecurityPolicy None on loopback only
(service/opcua/security.py, docs/opcua.md "Security"). asyncua's client against asyncua's
server configured by ``apply_security``, over real sockets."""

from __future__ import annotations

from pathlib import Path

import pytest
from asyncua import ua
from asyncua.client.client import Client
from asyncua.server.server import Server
from asyncua.ua.status_codes import StatusCodes
from asyncua.ua.uaerrors import UaError, UaStatusCodeError

from cnc_objects.protocol.roles import Role
from cnc_objects.service.opcua.security import OpcUaSecurityError, apply_security
from cnc_objects.service.opcua.security_config import OpcUaSecurity
from tests.support.opcua_security import (
    ANSWER,
    PASSWORDS,
    ClientIdentity,
    secure_client,
    secured_server,
)


def _settings(certificate_dir: Path, users_file: Path, **more: str) -> OpcUaSecurity:
    return OpcUaSecurity(certificate_dir=str(certificate_dir), users_file=str(users_file),
                         **more)


@pytest.mark.parametrize("mode", [ua.MessageSecurityMode.SignAndEncrypt,
                                  ua.MessageSecurityMode.Sign], ids=["sign-and-encrypt", "sign"])
async def test_a_trusted_client_reads_on_basic256sha256(
    certificate_dir: Path, users_file: Path, trusted: ClientIdentity,
    mode: ua.MessageSecurityMode,
) -> None:
    async with secured_server(_settings(certificate_dir, users_file)) as server:
        client = await secure_client(server.url, trusted, certificate_dir, mode, Role.OPERATOR)
        async with client:
            assert client.security_policy.Mode == mode
            assert await client.get_node(server.answer.nodeid).read_value() == ANSWER
        assert server.roles_read == [Role.OPERATOR]


@pytest.mark.parametrize("others_trusted", [True, False], ids=["others-trusted", "none-trusted"])
async def test_an_untrusted_client_certificate_is_refused(
    tmp_path: Path, certificate_dir: Path, users_file: Path, trusted: ClientIdentity,
    untrusted: ClientIdentity, others_trusted: bool,
) -> None:
    settings = _settings(certificate_dir, users_file)
    if not others_trusted:  # [opcua] trusted_clients_dir: an empty one of its own
        (tmp_path / "nobody").mkdir()
        settings = _settings(certificate_dir, users_file, trusted_clients_dir=str(tmp_path / "nobody"))
    async with secured_server(settings) as server:
        client = await secure_client(server.url, untrusted, certificate_dir, user=Role.ADMIN)
        with pytest.raises(UaStatusCodeError) as refused:
            await client.connect()
        assert refused.value.code == StatusCodes.BadCertificateUntrusted
        assert server.roles_read == []


async def test_a_channel_of_an_untrusted_certificate_cannot_name_a_trusted_one(
    certificate_dir: Path, users_file: Path, trusted: ClientIdentity, untrusted: ClientIdentity,
) -> None:
    """asyncua validates the certificate a client names in CreateSession, not the one that
    secures its channel: a stranger who names a trusted client's (public) certificate is
    refused at ActivateSession, where the channel's own certificate is checked."""
    async with secured_server(_settings(certificate_dir, users_file)) as server:
        client = await secure_client(server.url, untrusted, certificate_dir, user=Role.ADMIN)
        await client.connect_socket()
        try:
            await client.send_hello()
            await client.open_secure_channel()  # secured by the stranger's certificate
            params = ua.CreateSessionParameters()
            params.ClientNonce = b"n" * 32
            params.ClientCertificate = trusted.der  # ... naming the trusted one
            params.ClientDescription = ua.ApplicationDescription(
                ApplicationUri=trusted.uri, ApplicationType=ua.ApplicationType.Client)
            params.EndpointUrl = server.url
            params.SessionName = "borrowed certificate"
            params.RequestedSessionTimeout = 10_000
            created = await client.uaclient.create_session(params)
            client._server_nonce = created.ServerNonce  # what create_session would keep
            with pytest.raises(UaStatusCodeError) as refused:
                await client.activate_session(Role.ADMIN.label, PASSWORDS[Role.ADMIN])
            assert refused.value.code == StatusCodes.BadUserAccessDenied
        finally:
            client.disconnect_socket()
        assert server.roles_read == []


async def test_security_policy_none_is_refused_off_loopback(
    certificate_dir: Path, users_file: Path, trusted: ClientIdentity,
) -> None:
    server = Server()
    await server.init()
    with pytest.raises(OpcUaSecurityError, match="loopback only"):
        await apply_security(server, OpcUaSecurity(), "0.0.0.0")
    # with a certificate it serves the network, on the secured policies alone
    async with secured_server(_settings(certificate_dir, users_file), host="0.0.0.0") as served:
        policies = {e.SecurityPolicyUri.rsplit("#", 1)[1]: e for e in
                    await Client(served.url, timeout=10).connect_and_get_server_endpoints()}
        # (GetEndpoints needs no session: asyncua answers it on any channel)
        assert sorted(policies) == ["Basic256Sha256"]
        assert {e.SecurityMode for e in policies.values()} <= {
            ua.MessageSecurityMode.Sign, ua.MessageSecurityMode.SignAndEncrypt}
        plain = Client(served.url, timeout=10)  # SecurityPolicy None, anonymous
        with pytest.raises(UaError):
            await plain.connect()
        # and anonymous sessions are not offered off loopback, even on a secured channel
        tokens = {t.TokenType for e in policies.values() for t in e.UserIdentityTokens}
        assert tokens == {ua.UserTokenType.UserName}
        client = await secure_client(served.url, trusted, certificate_dir, user=Role.MONITOR)
        async with client:
            assert await client.get_node(served.answer.nodeid).read_value() == ANSWER
        assert served.roles_read == [Role.MONITOR]


async def test_a_security_policy_none_channel_gets_no_session_off_loopback(
    certificate_dir: Path, users_file: Path,
) -> None:
    """asyncua opens a SecurityPolicy None channel on any server (GetEndpoints needs one)
    and would create a session on it; off loopback no session is activated on it, not
    even with a right password."""
    async with secured_server(_settings(certificate_dir, users_file), host="0.0.0.0") as served:
        client = Client(served.url, timeout=10)  # SecurityPolicy None, no certificate
        await client.connect_socket()
        try:
            await client.send_hello()
            await client.open_secure_channel()
            params = ua.CreateSessionParameters()
            params.ClientNonce = b"n" * 32
            params.ClientDescription = ua.ApplicationDescription(
                ApplicationUri="urn:test:plain", ApplicationType=ua.ApplicationType.Client)
            params.EndpointUrl = served.url
            params.SessionName = "plain channel"
            params.RequestedSessionTimeout = 10_000
            created = await client.uaclient.create_session(params)
            client._server_nonce = created.ServerNonce
            client._policy_ids = [ua.UserTokenPolicy(  # the password in clear: no policy
                PolicyId="username", TokenType=ua.UserTokenType.UserName,
                SecurityPolicyUri="http://opcfoundation.org/UA/SecurityPolicy#None")]
            with pytest.raises(UaStatusCodeError) as refused:
                await client.activate_session(Role.OPERATOR.label, PASSWORDS[Role.OPERATOR])
            assert refused.value.code == StatusCodes.BadUserAccessDenied
        finally:
            client.disconnect_socket()
        assert served.roles_read == []


@pytest.mark.parametrize(("certificate", "loopback_role", "expected"), [
    (False, None, Role.ADMIN),  # a server without security: the ADS front end's loopback rule
    (True, None, Role.MONITOR),  # a server with a certificate gives anonymous the least
    (True, "operator", Role.OPERATOR),  # [opcua] loopback_role
], ids=["open", "with-certificate", "configured"])
async def test_loopback_serves_security_policy_none_and_anonymous_with_the_loopback_role(
    certificate_dir: Path, certificate: bool, loopback_role: str | None,
    expected: Role,
) -> None:
    settings = OpcUaSecurity(certificate_dir=str(certificate_dir) if certificate else None,
                             loopback_role=loopback_role)
    async with secured_server(settings) as server:
        async with Client(server.url, timeout=10) as client:
            assert client.security_policy.Mode == ua.MessageSecurityMode.None_
            assert await client.get_node(server.answer.nodeid).read_value() == ANSWER
        assert server.roles_read == [expected]


async def test_a_certificate_directory_that_is_not_one_is_refused_at_start(tmp_path: Path) -> None:
    server = Server()
    await server.init()
    with pytest.raises(OpcUaSecurityError, match=r"server-cert\.der does not exist .*cnc opcua-cert"):
        await apply_security(server, OpcUaSecurity(certificate_dir=str(tmp_path)), "127.0.0.1")
