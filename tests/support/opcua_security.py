"""An asyncua server secured by ``service/opcua/security.py`` and the clients that meet it.

The server is asyncua's own ``Server`` on a free port (port 0, asyncua takes the one the
system gave) with one variable, configured by ``apply_security`` exactly as the service
does; every Read it serves records the role ``role_of`` gives the session's user, which
is what the front end's writes and methods ask.
"""

from __future__ import annotations

from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from asyncua import ua
from asyncua.client.client import Client
from asyncua.common.callback import CallbackType, ServerItemCallback
from asyncua.crypto import cert_gen
from asyncua.crypto.security_policies import SecurityPolicyBasic256Sha256
from asyncua.server.server import Server
from cryptography import x509
from cryptography.hazmat.primitives.serialization import Encoding
from cryptography.x509.oid import ExtendedKeyUsageOID

from cnc_objects.clients.web.users import WebUsers, save_users
from cnc_objects.protocol.opcua_files import CERTIFICATE_FILE
from cnc_objects.protocol.roles import Role
from cnc_objects.service.opcua.security import apply_security, role_of
from cnc_objects.service.opcua.security_config import OpcUaSecurity

ANSWER = 42  # the value of the one variable the server serves
PASSWORDS = {Role.MONITOR: "m-secret", Role.OPERATOR: "o-secret", Role.ADMIN: "a-secret"}


@dataclass(frozen=True)
class ClientIdentity:
    """A client application's certificate (DER file), key (PEM file) and URI."""

    certificate: Path
    private_key: Path
    uri: str

    @property
    def der(self) -> bytes:
        """The certificate's bytes."""
        return self.certificate.read_bytes()


def make_client_identity(directory: Path, name: str) -> ClientIdentity:
    """A self-signed client certificate as OPC UA clients make them (asyncua's cert_gen)."""
    uri = f"urn:test:{name}"
    key = cert_gen.generate_private_key()
    certificate = cert_gen.generate_self_signed_app_certificate(
        key, name, {}, [x509.UniformResourceIdentifier(uri), x509.DNSName("localhost")],
        [ExtendedKeyUsageOID.CLIENT_AUTH])
    directory.mkdir(parents=True, exist_ok=True)
    cert_path, key_path = directory / f"{name}.der", directory / f"{name}.pem"
    cert_path.write_bytes(certificate.public_bytes(Encoding.DER))
    key_path.write_bytes(cert_gen.dump_private_key_as_pem(key))
    return ClientIdentity(cert_path, key_path, uri)


def write_users_file(path: Path) -> Path:
    """A web users file with a password for each role (``PASSWORDS``)."""
    users = WebUsers()
    for role, password in PASSWORDS.items():
        users.set_password(role, password)
    save_users(path, users)
    return path


@dataclass
class SecuredServer:
    """The running server: its URL and the roles of the sessions that read."""

    server: Server
    url: str
    answer: Any  # the variable's node
    roles_read: list[Role] = field(default_factory=list)


@asynccontextmanager
async def secured_server(settings: OpcUaSecurity, host: str = "127.0.0.1",
                         connect_host: str = "127.0.0.1") -> AsyncIterator[SecuredServer]:
    """asyncua's server on ``host`` (a free port), secured by ``apply_security``; its URL
    names ``connect_host``."""
    server = Server()
    await server.init()
    server.set_endpoint(f"opc.tcp://{host}:0/cnc/")
    namespace = await server.register_namespace("urn:test:opcua-security")
    answer = await server.nodes.objects.add_variable(namespace, "Answer", ANSWER)
    await apply_security(server, settings, host)
    running = SecuredServer(server, "", answer)

    async def note_role(event: ServerItemCallback, _: Any) -> None:
        if event.is_external:
            running.roles_read.append(role_of(event.user))

    server.subscribe_server_callback(CallbackType.PreRead, note_role)
    await server.start()
    try:
        assert server.bserver is not None
        running.url = f"opc.tcp://{connect_host}:{server.bserver.port}/cnc/"
        yield running
    finally:
        await server.stop()


async def secure_client(url: str, identity: ClientIdentity, certificate_dir: Path,
                        mode: ua.MessageSecurityMode = ua.MessageSecurityMode.SignAndEncrypt,
                        user: Role | None = None, password: str | None = None) -> Client:
    """A client (not connected) on Basic256Sha256 ``mode`` with ``identity``, trusting the
    server's certificate of ``certificate_dir``, signing in as ``user`` when given."""
    client = Client(url, timeout=10)
    client.application_uri = identity.uri
    await client.set_security(SecurityPolicyBasic256Sha256, str(identity.certificate),
                              str(identity.private_key),
                              server_certificate=str(certificate_dir / CERTIFICATE_FILE),
                              mode=mode)
    if user is not None:
        client.set_user(user.label)
        client.set_password(password if password is not None else PASSWORDS[user])
    return client
