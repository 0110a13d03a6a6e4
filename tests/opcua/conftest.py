"""Services with the OPC UA front end on a free loopback port, and asyncua clients of them."""

from __future__ import annotations

import re
import shutil
from collections.abc import AsyncIterator, Iterator
from pathlib import Path

import pytest
from asyncua import Client, Node

from cnc_objects.protocol.opcua_files import TRUSTED_DIR
from cnc_objects.testing import ServiceProcess, serving
from tests.support.cli import cnc
from tests.support.opcua_security import ClientIdentity, make_client_identity, write_users_file

CNC_URI = "http://opcfoundation.org/UA/CNC"
OPCUA_ANY_PORT = ("--opcua", "opc.tcp://127.0.0.1:0")
_OPCUA_LOG = r"OPC UA on (opc\.tcp://\S+)"
#: A cold start imports the nodesets (seconds, more under load) before it caches them.
OPCUA_START_S = 120.0


def opcua_url(service: ServiceProcess) -> str:
    """The URL the service's OPC UA front end logged."""
    match = re.search(_OPCUA_LOG, service.wait_for_log(_OPCUA_LOG))
    assert match is not None
    return match.group(1)


@pytest.fixture(scope="session", autouse=True)
def _address_space_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """The services of these tests keep their OPC UA address space cache in a directory
    of the test session, not in the user's ~/.cache (the first start imports, the others
    load it)."""
    directory = tmp_path_factory.mktemp("opcua-cache")
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("CNC_OPCUA_CACHE_DIR", str(directory))
        yield directory


@pytest.fixture(scope="module")
def opcua_service() -> Iterator[ServiceProcess]:
    """A service with OPC UA for the tests of one module (the loopback role: admin)."""
    with serving(*OPCUA_ANY_PORT, timeout_s=OPCUA_START_S) as service:
        yield service


@pytest.fixture
async def ua_client(opcua_service: ServiceProcess) -> AsyncIterator[Client]:
    """An asyncua client connected to ``opcua_service``."""
    async with Client(opcua_url(opcua_service), timeout=30) as client:
        yield client


@pytest.fixture(scope="module")
def monitor_service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    """A service whose OPC UA sessions are monitors ([opcua] loopback_role)."""
    work: Path = tmp_path_factory.mktemp("opcua-monitor")
    config = work / "machine.toml"
    config.write_text('[opcua]\nloopback_role = "monitor"\n')
    with serving("--config", str(config), *OPCUA_ANY_PORT, timeout_s=OPCUA_START_S) as service:
        yield service


async def cnc_node(client: Client, *path: str) -> Node:
    """The node at ``path`` (browse names in the CNC namespace) under Objects."""
    ns = await client.get_namespace_index(CNC_URI)
    return await client.nodes.objects.get_child([f"{ns}:{name}" for name in path])


# The security fixtures: made once per module (RSA keys and Argon2 hashes take a while,
# and no test changes them).
@pytest.fixture(scope="module")
def certificate_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The server's certificate, made by ``cnc opcua-cert`` (its ``trusted/`` empty)."""
    directory = tmp_path_factory.mktemp("server") / "opcua"
    made = cnc("opcua-cert", "--dir", str(directory), "--host", "localhost")
    assert made.returncode == 0, made.stderr
    return directory


@pytest.fixture(scope="module")
def trusted(tmp_path_factory: pytest.TempPathFactory, certificate_dir: Path) -> ClientIdentity:
    """A client whose certificate is in the server's trusted directory."""
    identity = make_client_identity(tmp_path_factory.mktemp("client"), "trusted-client")
    shutil.copy(identity.certificate, certificate_dir / TRUSTED_DIR)
    return identity


@pytest.fixture(scope="module")
def untrusted(tmp_path_factory: pytest.TempPathFactory) -> ClientIdentity:
    """A client whose certificate the server has never seen."""
    return make_client_identity(tmp_path_factory.mktemp("stranger"), "stranger")


@pytest.fixture(scope="module")
def users_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A web users file with a password for each role (``PASSWORDS``)."""
    return write_users_file(tmp_path_factory.mktemp("users") / "web-users.json")
