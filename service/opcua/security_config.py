"""The security keys of the OPC UA front end's ``[opcua]`` table (docs/opcua.md,
"Security"), apart from ``security.py``: the configuration is loaded without asyncua."""

from __future__ import annotations

from pydantic import Field

from ..frontend_config import RoleName
from ..machine_config import Strict


class OpcUaSecurity(Strict):
    """The security keys of ``[opcua]``. Relative paths are taken from the working
    directory at start."""

    certificate_dir: str | None = Field(
        None, description="directory of the application certificate (cnc opcua-cert): "
        "Basic256Sha256 Sign and SignAndEncrypt on; needed on a non-loopback host",
    )
    trusted_clients_dir: str | None = Field(
        None, description="certificates (DER or PEM) of the clients that may connect "
        "(default: certificate_dir/trusted)",
    )
    users_file: str | None = Field(
        None, description="the web users file (cnc web-users set ROLE): user name = role, "
        "its password; none: no user name tokens",
    )
    loopback_role: RoleName | None = Field(
        None, description="role of anonymous sessions, allowed on a loopback host only "
        "(default: admin; monitor when certificate_dir is given)",
    )
