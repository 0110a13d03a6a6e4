"""``cnc opcua-cert``: the application certificate of the service's OPC UA front end
(docs/opcua.md, "Security").

    cnc opcua-cert --dir /etc/cnc/opcua --uri urn:mill-7:cnc-objects --host mill-7

writes into DIR the certificate ``server-cert.der`` (DER, self-signed, the application URI
in its subjectAltName as OPC UA requires, made by asyncua's ``cert_gen``), its private key
``server-key.pem`` (mode 0600) and an empty ``trusted/`` for the certificates of the
clients that may connect. ``[opcua] certificate_dir = "DIR"`` serves it. A command of its
own beside ``cnc keys``: those are CURVE key pairs of ZeroMQ, this is an X.509 certificate.
"""

from __future__ import annotations

import ipaddress
import os
import re
import socket
from pathlib import Path

import typer

from cnc_objects.protocol.opcua_files import (
    CERTIFICATE_DAYS,
    CERTIFICATE_FILE,
    DEFAULT_CERTIFICATE_DIR,
    PRIVATE_KEY_FILE,
    TRUSTED_DIR,
)

from .app import EXIT_USAGE, Settings, app, emit, say_error

_LABEL = r"[A-Za-z0-9](?:[A-Za-z0-9-]{0,61}[A-Za-z0-9])?"
_DNS_NAME = re.compile(rf"{_LABEL}(?:\.{_LABEL})*")  # RFC 1123 host names


def _usage(text: str) -> typer.Exit:
    say_error(text)
    return typer.Exit(EXIT_USAGE)


@app.command("opcua-cert")
def opcua_cert(
    ctx: typer.Context,
    directory: Path = typer.Option(
        Path(DEFAULT_CERTIFICATE_DIR), "--dir", metavar="DIR",
        help=f"Where {CERTIFICATE_FILE}, {PRIVATE_KEY_FILE} and {TRUSTED_DIR}/ go.",
    ),
    uri: str | None = typer.Option(
        None, "--uri", metavar="URI",
        help="The server's application URI (default urn:HOSTNAME:cnc-objects).",
    ),
    hosts: list[str] | None = typer.Option(
        None, "--host", metavar="NAME",
        help="A DNS name or IP address clients reach the server by; repeat for more "
        "(default: this machine's name and localhost).",
    ),
    days: int = typer.Option(CERTIFICATE_DAYS, "--days", min=1, metavar="N",
                             help="How long the certificate is valid."),
    force: bool = typer.Option(False, "--force", help="Replace a certificate already there."),
) -> None:
    """Make the OPC UA application certificate and key of cnc-service (Basic256Sha256).

    Serve it with [opcua] certificate_dir = "DIR" and put the certificate of each client
    that may connect into DIR/trusted. Give the clients DIR/server-cert.der to trust.
    """
    settings: Settings = ctx.find_root().obj
    hostname = socket.gethostname()
    application_uri = uri if uri is not None else f"urn:{hostname}:cnc-objects"
    # this machine's name only where a certificate can carry it (not my_pc, say)
    names = hosts or [n for n in (hostname, "localhost") if _DNS_NAME.fullmatch(n)]
    if ":" not in application_uri:
        raise _usage(f"--uri {application_uri!r}: an application URI has a scheme (urn:...)")
    for name in names:
        if not _is_address(name) and not _DNS_NAME.fullmatch(name):
            raise _usage(f"--host {name!r}: give a DNS name (letters, digits, '-', '.') or an "
                         "IP address")
    certificate_file = directory / CERTIFICATE_FILE
    key_file = directory / PRIVATE_KEY_FILE
    trusted = directory / TRUSTED_DIR
    for path in (certificate_file, key_file):
        if path.exists() and not force:
            raise _usage(f"{path} exists; --force replaces it (clients that trust the old "
                         "certificate must be given the new one)")
    # here: the other commands start without asyncua and cryptography
    from asyncua.crypto import cert_gen
    from cryptography import x509
    from cryptography.hazmat.primitives.serialization import Encoding
    from cryptography.x509.oid import ExtendedKeyUsageOID

    alt_names: list[x509.GeneralName] = [x509.UniformResourceIdentifier(application_uri)]
    alt_names += [x509.IPAddress(ipaddress.ip_address(name)) if _is_address(name)
                  else x509.DNSName(name) for name in names]
    key = cert_gen.generate_private_key()
    certificate = cert_gen.generate_self_signed_app_certificate(
        key, "cnc-objects", {}, alt_names,
        [ExtendedKeyUsageOID.SERVER_AUTH, ExtendedKeyUsageOID.CLIENT_AUTH], days=days)
    try:
        trusted.mkdir(parents=True, exist_ok=True)
        _write(key_file, cert_gen.dump_private_key_as_pem(key), 0o600)
        _write(certificate_file, certificate.public_bytes(Encoding.DER), 0o644)
    except OSError as exc:
        raise _usage(f"cannot write into {directory}: {exc.strerror or exc}") from None
    until = certificate.not_valid_after_utc.date().isoformat()
    emit(settings, {
        "certificate": str(certificate_file), "private_key": str(key_file),
        "trusted_dir": str(trusted), "application_uri": application_uri,
        "hosts": names, "valid_until": until,
    }, "\n".join([
        f"wrote {certificate_file} (application certificate, DER; application URI "
        f"{application_uri}; hosts {', '.join(names)}; valid until {until})",
        f"wrote {key_file} (private key, mode 0600: it stays with the service)",
        f"clients that may connect: put their certificates into {trusted}/",
        f"serve it: [opcua] certificate_dir = \"{directory}\" (restart cnc-service)",
    ]))


def _is_address(name: str) -> bool:
    try:
        ipaddress.ip_address(name)
    except ValueError:
        return False
    return True


def _write(path: Path, data: bytes, mode: int) -> None:
    """``data`` into ``path`` with ``mode`` from the start (the key is never readable by
    others, not even for a moment), replacing a file of that name."""
    temporary = path.with_name(f".{path.name}.{os.getpid()}")
    fd = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, mode)
    try:
        with os.fdopen(fd, "wb") as out:
            out.write(data)
        os.chmod(temporary, mode)  # the umask may have taken bits of the certificate's
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise

