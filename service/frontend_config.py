"""The front ends' configuration: the ADS listener and its routes (``[ads]``), CURVE keys
and the allow-list (``[security]``). The kernel never sees it."""

from __future__ import annotations

import ipaddress
from typing import Literal

from pydantic import Field, field_validator

from cnc_objects.protocol.ams import parse_net_id
from cnc_objects.protocol.constants import AMS_MAX_FRAME_BYTES, AMS_TCP_PORT

from .machine_config import Strict


def parse_ads_endpoint(text: str) -> tuple[str, int] | None:
    """``HOST[:PORT]`` of the ADS listener as (host, port), port 48898 when left out;
    None for ``off``. IPv6 hosts in brackets (``[::1]:48898``). Port 0 takes any free
    port. ``ValueError`` says what is wrong."""
    text = text.strip()
    if text.lower() == "off":
        return None
    port_text = ""
    if text.startswith("["):
        host, sep, rest = text[1:].partition("]")
        if not sep or (rest and not rest.startswith(":")):
            raise ValueError(f"{text!r}: write an IPv6 host as [addr] or [addr]:port")
        port_text = rest[1:]
    else:
        host, _, port_text = text.partition(":")
        if ":" in port_text:
            raise ValueError(f"{text!r}: write an IPv6 host in brackets, [addr]:port")
    if not host:
        raise ValueError(f"{text!r}: the host is missing (HOST[:PORT], or off)")
    if not port_text:
        return host, AMS_TCP_PORT
    if not port_text.isdigit() or int(port_text) > 0xFFFF:
        raise ValueError(f"{text!r}: the port must be a number 0..65535")
    return host, int(port_text)


RoleName = Literal["monitor", "operator", "admin"]  # protocol.roles.Role, as written
_Z85_KEY_CHARS = 40  # a CURVE key (32 bytes) in Z85 text
_Z85_ALPHABET = frozenset(
    "0123456789abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ.-:+=^!/*?&<>()[]{}@%$#")


def _checked_net_id(value: str) -> str:
    """An AMS Net ID of the configuration, stripped (``ValueError`` when it is none)."""
    parse_net_id(value)
    return value.strip()


class AdsRouteConfig(Strict):
    """A route of the ADS front end: a peer that may connect from ``address``."""

    name: str = Field(min_length=1, max_length=63, description="name of the route")
    net_id: str = Field(description="AMS Net ID the peer sends from (a.b.c.d.e.f)")
    address: str = Field(description="IP address the peer connects from")
    role: RoleName = Field(
        "operator",
        description="what the peer may do: monitor, operator or admin (docs/security.md)",
    )

    @field_validator("net_id")
    @classmethod
    def _net_id(cls, value: str) -> str:
        return _checked_net_id(value)

    @field_validator("address")
    @classmethod
    def _address(cls, value: str) -> str:
        try:
            return str(ipaddress.ip_address(value.strip()))
        except ValueError:
            raise ValueError(f"{value!r} is not an IP address") from None


class AdsConfig(Strict):
    """The ADS front end (AMS/TCP): where it listens, its AMS Net ID, its routes."""

    endpoint: str = Field(
        f"127.0.0.1:{AMS_TCP_PORT}",
        description="HOST[:PORT] to listen on for ADS (AMS/TCP), or off",
    )
    net_id: str | None = Field(
        None, description="AMS Net ID of the service (default: the bound IPv4 address + .1.1)"
    )
    routes: tuple[AdsRouteConfig, ...] = Field(
        (), description="peers served besides loopback (name, net_id, address)"
    )
    max_frame_bytes: int = Field(
        AMS_MAX_FRAME_BYTES, ge=1024, le=64 << 20,
        description="longest AMS/TCP frame a client may send (bytes); longer closes it",
    )
    loopback_role: RoleName | None = Field(
        None, description="role of ADS peers on loopback (default: admin; monitor when the "
        "service runs with keys)"
    )

    @field_validator("endpoint")
    @classmethod
    def _endpoint(cls, value: str) -> str:
        parse_ads_endpoint(value)
        return value.strip()

    @field_validator("net_id")
    @classmethod
    def _net_id(cls, value: str | None) -> str | None:
        return None if value is None else _checked_net_id(value)

    @property
    def address(self) -> tuple[str, int] | None:
        """(host, port) to listen on, None when ADS is off."""
        return parse_ads_endpoint(self.endpoint)


class ClientKeyConfig(Strict):
    """A client of the allow-list given in the configuration instead of a key file."""

    name: str = Field(min_length=1, max_length=63, description="name of the client (logs)")
    public_key: str = Field(description="the client's CURVE public key, 40 Z85 characters")
    role: RoleName = Field(description="what the client may do: monitor, operator or admin")

    @field_validator("public_key")
    @classmethod
    def _z85_key(cls, value: str) -> str:
        value = value.strip()
        if len(value) != _Z85_KEY_CHARS or not set(value) <= _Z85_ALPHABET:
            raise ValueError(f"must be the {_Z85_KEY_CHARS} Z85 characters of a CURVE public "
                             "key (the public-key line of NAME.key)")
        return value


class SecurityConfig(Strict):
    """CURVE keys of the ZeroMQ front end (docs/security.md); ``--keys DIR`` beats
    ``keys_dir``. Relative paths are taken from the working directory at start."""

    keys_dir: str | None = Field(
        None, description="directory of server.key_secret and clients/<role>/*.key: CURVE on"
    )
    server_secret_key_file: str | None = Field(
        None, description="the service's secret key file (default: keys_dir/server.key_secret)"
    )
    clients_dir: str | None = Field(
        None, description="allow-list directory clients/<role>/*.key (default: keys_dir/clients)"
    )
    clients: tuple[ClientKeyConfig, ...] = Field(
        (), description="allow-list entries besides the directory's (name, public_key, role)"
    )

    @property
    def curve(self) -> bool:
        """True when the configuration turns CURVE on."""
        return bool(self.keys_dir or self.server_secret_key_file)
