"""The real service with OPC UA security on, as a plant would run it: the certificate
`cnc opcua-cert` made, a trusted client certificate, the web users file's passwords.

A client on Basic256Sha256 SignAndEncrypt signs in as operator and writes the feed
override (the kernel applies it: the ZeroMQ front end reads it back); as monitor the same
write is BadUserAccessDenied and nothing changes; an untrusted client certificate gets no
session; anonymous sessions on loopback are monitors once the server has a certificate.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
from asyncua import Client, Node, ua

from cnc_objects.clients import Client as CncClient
from cnc_objects.protocol.roles import Role
from cnc_objects.testing import ServiceProcess, serving
from tests.support.opcua_security import ClientIdentity, secure_client

from .conftest import OPCUA_ANY_PORT, OPCUA_START_S, cnc_node, opcua_url

FEED_OVERRIDE = ("CncChannelList", "Channel1", "CmdOverride")  # writes ..._feed_override_w


@dataclass(frozen=True)
class Secured:
    """The service, its certificate directory and the client identities."""

    service: ServiceProcess
    certificate_dir: Path
    trusted: ClientIdentity
    stranger: ClientIdentity


@pytest.fixture(scope="module")
def secured(tmp_path_factory: pytest.TempPathFactory, certificate_dir: Path,
            trusted: ClientIdentity, untrusted: ClientIdentity,
            users_file: Path) -> Iterator[Secured]:
    config = tmp_path_factory.mktemp("opcua-secured") / "machine.toml"
    config.write_text(f'[opcua]\ncertificate_dir = "{certificate_dir}"\n'
                      f'users_file = "{users_file}"\n')
    with serving("--config", str(config), *OPCUA_ANY_PORT,
                 timeout_s=OPCUA_START_S) as service:
        yield Secured(service, certificate_dir, trusted, untrusted)


async def _override_node(client: Client) -> Node:
    return await cnc_node(client, "CncInterface", *FEED_OVERRIDE)


def _override_per_mille(service: ServiceProcess) -> int:
    with CncClient(service.endpoint) as cnc:
        return int(cnc.read("ch1.mc_command_feed_override_w"))


async def test_an_operator_on_sign_and_encrypt_writes_the_override(secured: Secured) -> None:
    client = await secure_client(opcua_url(secured.service), secured.trusted,
                                 secured.certificate_dir, user=Role.OPERATOR)
    async with client:
        node = await _override_node(client)
        await node.write_value(ua.DataValue(ua.Variant(55.0, ua.VariantType.Double)))
        assert await node.read_value() == pytest.approx(55.0)
    assert _override_per_mille(secured.service) == 550
    client = await secure_client(opcua_url(secured.service), secured.trusted,
                                 secured.certificate_dir, mode=ua.MessageSecurityMode.Sign,
                                 user=Role.OPERATOR)
    async with client:  # Sign alone serves too
        node = await _override_node(client)
        await node.write_value(ua.DataValue(ua.Variant(100.0, ua.VariantType.Double)))
    assert _override_per_mille(secured.service) == 1000


async def test_a_monitor_may_read_but_not_write(secured: Secured) -> None:
    client = await secure_client(opcua_url(secured.service), secured.trusted,
                                 secured.certificate_dir, user=Role.MONITOR)
    async with client:
        node = await _override_node(client)
        assert await node.read_value() == pytest.approx(100.0)
        with pytest.raises(ua.uaerrors.BadUserAccessDenied):
            await node.write_value(ua.DataValue(ua.Variant(20.0, ua.VariantType.Double)))
    assert _override_per_mille(secured.service) == 1000


async def test_a_wrong_password_and_an_untrusted_certificate_get_no_session(
        secured: Secured) -> None:
    url = opcua_url(secured.service)
    wrong = await secure_client(url, secured.trusted, secured.certificate_dir,
                                user=Role.OPERATOR, password="guess")
    with pytest.raises(ua.UaError):
        async with wrong:
            pass
    stranger = await secure_client(url, secured.stranger, secured.certificate_dir,
                                   user=Role.OPERATOR)
    with pytest.raises((ua.UaError, OSError, TimeoutError)):
        async with stranger:
            pass
    assert secured.service.process.poll() is None


async def test_anonymous_on_loopback_is_a_monitor_once_there_is_a_certificate(
        secured: Secured) -> None:
    async with Client(opcua_url(secured.service), timeout=30) as client:
        node = await _override_node(client)
        assert await node.read_value() == pytest.approx(100.0)
        with pytest.raises(ua.uaerrors.BadUserAccessDenied):
            await node.write_value(ua.DataValue(ua.Variant(20.0, ua.VariantType.Double)))
