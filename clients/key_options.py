"""The ``--key`` and ``--server-key`` options of the long-running clients (cnc-hmi,
cnc-mqtt): one definition, each command naming whose key it is in the help."""

from __future__ import annotations

from typing import Any

import typer


def key_option(whose: str) -> Any:
    """``--key FILE`` (``$CNC_KEY``): the CURVE secret key file of ``whose`` ("The HMI's")."""
    return typer.Option(
        None, "--key", metavar="FILE", envvar="CNC_KEY",
        help=f"{whose} CURVE secret key file, for a service with --keys (default $CNC_KEY).",
    )


def server_key_option() -> Any:
    """``--server-key FILE`` (``$CNC_SERVER_KEY``): the service's public key file."""
    return typer.Option(
        None, "--server-key", metavar="FILE", envvar="CNC_SERVER_KEY",
        help="The service's public key file (default $CNC_SERVER_KEY, else server.key "
        "beside --key).",
    )
