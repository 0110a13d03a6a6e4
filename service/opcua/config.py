"""The OPC UA front end's configuration (``[opcua]``, ``--opcua``). Pure data: no asyncua."""

from __future__ import annotations

import ipaddress
from urllib.parse import urlsplit

from pydantic import Field, field_validator

from .security_config import OpcUaSecurity

OPCUA_SCHEME = "opc.tcp"
OPCUA_PORT = 4840  # IANA's port of OPC UA over TCP, the default of every client
DEFAULT_OPCUA_ENDPOINT = f"{OPCUA_SCHEME}://127.0.0.1:{OPCUA_PORT}"


def parse_opcua_endpoint(text: str) -> tuple[str, int] | None:
    """``opc.tcp://HOST[:PORT]`` as (host, port), port 4840 when left out; None for
    ``off``. IPv6 hosts in brackets. Port 0 takes any free port. ``ValueError`` says
    what is wrong."""
    text = text.strip()
    if text.lower() == "off":
        return None
    try:
        parts = urlsplit(text)
        port = parts.port
    except ValueError as exc:  # a port that is no number or beyond 65535
        raise ValueError(f"{text!r}: {exc} (opc.tcp://HOST[:PORT], or off)") from None
    if parts.scheme != OPCUA_SCHEME:
        raise ValueError(f"{text!r}: the URL must begin with {OPCUA_SCHEME}:// "
                         "(opc.tcp://HOST[:PORT], or off)")
    if not parts.hostname:
        raise ValueError(f"{text!r}: the host is missing (opc.tcp://HOST[:PORT], or off)")
    if parts.path not in ("", "/") or parts.query or parts.fragment:
        raise ValueError(f"{text!r}: the service takes no path after the port "
                         "(opc.tcp://HOST[:PORT])")
    return parts.hostname, OPCUA_PORT if port is None else port


def endpoint_url(host: str, port: int) -> str:
    """``opc.tcp://host:port`` (an IPv6 host in brackets)."""
    try:
        bracket = ipaddress.ip_address(host).version == 6
    except ValueError:
        bracket = False
    return f"{OPCUA_SCHEME}://[{host}]:{port}" if bracket else f"{OPCUA_SCHEME}://{host}:{port}"


class OpcUaConfig(OpcUaSecurity):
    """The OPC UA front end: where it listens, and its security (``OpcUaSecurity``:
    certificate, trusted clients, users, the role of anonymous loopback sessions)."""

    endpoint: str = Field(
        DEFAULT_OPCUA_ENDPOINT,
        description="opc.tcp://HOST[:PORT] to listen on for OPC UA, or off",
    )

    @field_validator("endpoint")
    @classmethod
    def _endpoint(cls, value: str) -> str:
        parse_opcua_endpoint(value)
        return value.strip()

    @property
    def address(self) -> tuple[str, int] | None:
        """(host, port) to listen on, None when OPC UA is off."""
        return parse_opcua_endpoint(self.endpoint)
