"""``cnc opcua-cert``: the OPC UA application certificate, its key (0600) and the trusted
clients directory, as the service reads them (clients/cli/opcua_cert.py)."""

from __future__ import annotations

import json
import stat
from pathlib import Path

import pytest
from asyncua.server.server import Server
from cryptography import x509
from cryptography.hazmat.primitives.asymmetric import rsa
from cryptography.hazmat.primitives.serialization import load_pem_private_key
from cryptography.x509.oid import ExtendedKeyUsageOID

from cnc_objects.service.opcua.security import apply_security
from cnc_objects.service.opcua.security_config import OpcUaSecurity
from tests.support.cli import cnc

URI = "urn:mill-7:cnc-objects"


def _mode(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


async def test_opcua_cert_writes_the_certificate_the_key_and_the_trusted_directory(
    tmp_path: Path,
) -> None:
    directory = tmp_path / "opcua"
    made = cnc("opcua-cert", "--dir", str(directory), "--uri", URI, "--host", "mill-7",
               "--host", "192.0.2.7", "--days", "30")
    assert made.returncode == 0, made.stderr
    certificate_file, key_file = directory / "server-cert.der", directory / "server-key.pem"
    assert made.stdout.splitlines() == [
        f"wrote {certificate_file} (application certificate, DER; application URI {URI}; "
        f"hosts mill-7, 192.0.2.7; valid until {_until(certificate_file)})",
        f"wrote {key_file} (private key, mode 0600: it stays with the service)",
        f"clients that may connect: put their certificates into {directory / 'trusted'}/",
        f'serve it: [opcua] certificate_dir = "{directory}" (restart cnc-service)',
    ]
    assert _mode(key_file) == 0o600
    assert _mode(certificate_file) == 0o644
    assert (directory / "trusted").is_dir() and not any((directory / "trusted").iterdir())
    assert sorted(p.name for p in directory.iterdir()) == [
        "server-cert.der", "server-key.pem", "trusted"]  # no temporary file left behind
    certificate = x509.load_der_x509_certificate(certificate_file.read_bytes())
    names = certificate.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    assert names.get_values_for_type(x509.UniformResourceIdentifier) == [URI]
    assert names.get_values_for_type(x509.DNSName) == ["mill-7"]
    assert [str(a) for a in names.get_values_for_type(x509.IPAddress)] == ["192.0.2.7"]
    usage = certificate.extensions.get_extension_for_class(x509.ExtendedKeyUsage).value
    assert ExtendedKeyUsageOID.SERVER_AUTH in usage
    validity = certificate.not_valid_after_utc - certificate.not_valid_before_utc
    assert validity.days == 30
    key = load_pem_private_key(key_file.read_bytes(), None)
    assert isinstance(key, rsa.RSAPrivateKey) and key.key_size == 2048  # Basic256Sha256
    public = certificate.public_key()
    assert isinstance(public, rsa.RSAPublicKey)
    assert key.public_key().public_numbers() == public.public_numbers()
    # the service serves it under the certificate's application URI
    server = Server()
    await server.init()
    await apply_security(server, OpcUaSecurity(certificate_dir=str(directory)), "127.0.0.1")
    assert server.get_application_uri() == URI


def _until(certificate_file: Path) -> str:
    certificate = x509.load_der_x509_certificate(certificate_file.read_bytes())
    return certificate.not_valid_after_utc.date().isoformat()


def test_opcua_cert_keeps_a_certificate_unless_forced(tmp_path: Path) -> None:
    directory = tmp_path / "opcua"
    assert cnc("opcua-cert", "--dir", str(directory)).returncode == 0
    first = (directory / "server-cert.der").read_bytes()
    again = cnc("opcua-cert", "--dir", str(directory))
    assert again.returncode == 2
    assert again.stderr.startswith(f"error: {directory / 'server-cert.der'} exists; --force")
    assert (directory / "server-cert.der").read_bytes() == first
    forced = cnc("--json", "opcua-cert", "--dir", str(directory), "--force", "--uri", URI)
    assert forced.returncode == 0, forced.stderr
    record = json.loads(forced.stdout)
    assert record["certificate"] == str(directory / "server-cert.der")
    assert record["private_key"] == str(directory / "server-key.pem")
    assert record["trusted_dir"] == str(directory / "trusted")
    assert record["application_uri"] == URI
    assert (directory / "server-cert.der").read_bytes() != first
    assert _mode(directory / "server-key.pem") == 0o600


@pytest.mark.parametrize(("option", "value", "problem"), [
    ("--uri", "mill-7", "an application URI has a scheme"),
    ("--host", "", "give a DNS name"),
    ("--host", "bad name!", "give a DNS name"),
])
def test_opcua_cert_refuses_a_uri_or_host_a_certificate_cannot_carry(
    tmp_path: Path, option: str, value: str, problem: str,
) -> None:
    refused = cnc("opcua-cert", "--dir", str(tmp_path / "opcua"), option, value)
    assert refused.returncode == 2
    assert problem in refused.stderr
    assert not (tmp_path / "opcua").exists()
