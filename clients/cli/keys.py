"""``cnc keys new``: CURVE key pairs for the service and its clients (docs/security.md).

    cnc keys new server --dir /etc/cnc/keys                    # the service's key pair
    cnc keys new alice --dir ~/.cnc --role operator --allow-in /etc/cnc/keys

Key files are ZeroMQ certificates written by ``zmq.auth.create_certificates``:
``NAME.key`` (public) and ``NAME.key_secret`` (secret, made readable by its owner only).
``--allow-in DIR`` also puts the public key into the allow-list of the service whose
``--keys`` directory is DIR, as ``DIR/clients/ROLE/NAME.key``, and copies the service's
public key ``DIR/server.key`` beside the new key, where the clients look for it.
"""

from __future__ import annotations

import inspect
import re
import shutil
from pathlib import Path

import typer

from cnc_objects.protocol.roles import ROLE_NAMES, Role

from ..key_files import PUBLIC_SUFFIX, SECRET_SUFFIX, SERVER_KEY_FILE
from .app import EXIT_USAGE, Settings, app, emit, say_error

CLIENTS_DIR = "clients"  # DIR/clients/<role>/<name>.key: the service's allow-list
_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,62}")

keys_app = typer.Typer(
    add_completion=False, no_args_is_help=True,
    help="Make CURVE key pairs for a service started with --keys and for its clients.",
)
app.add_typer(keys_app, name="keys")


def _usage(text: str) -> typer.Exit:
    say_error(text)
    return typer.Exit(EXIT_USAGE)


def new(
    ctx: typer.Context,
    name: str = typer.Argument(
        ..., metavar="NAME", help="Name of the key: server for the service, or a client's."
    ),
    directory: Path = typer.Option(
        Path("."), "--dir", metavar="DIR", help="Where NAME.key and NAME.key_secret go."
    ),
    role: str | None = typer.Option(
        None, "--role", metavar="ROLE",
        help=f"With --allow-in: what the client may do, one of {ROLE_NAMES} (default monitor).",
    ),
    allow_in: Path | None = typer.Option(
        None, "--allow-in", metavar="KEYS_DIR",
        help="Put the public key into the allow-list of the service whose --keys directory "
        "is KEYS_DIR (KEYS_DIR/clients/ROLE/NAME.key) and copy its server.key beside the key.",
    ),
    force: bool = typer.Option(False, "--force", help="Replace keys of the same name."),
) -> None:
    """Write a new CURVE key pair NAME.key (public) and NAME.key_secret (secret).

    The service's pair is named server (cnc-service --keys DIR reads DIR/server.key_secret);
    a client's public key goes into the service's allow-list with --allow-in and --role. A
    service reads its allow-list at start: restart it to admit a new key.
    """
    settings: Settings = ctx.find_root().obj
    if not _NAME.fullmatch(name):
        raise _usage(f"key name {name!r}: letters, digits, '.', '_' and '-', at most 63")
    if role is not None and allow_in is None:
        raise _usage("--role says what a client may do in a service's allow-list: give "
                     "--allow-in KEYS_DIR (the service's --keys directory) too")
    try:
        granted = Role.parse(role) if role is not None else Role.MONITOR
    except ValueError as exc:
        raise _usage(str(exc)) from None
    public = directory / f"{name}{PUBLIC_SUFFIX}"
    secret = directory / f"{name}{SECRET_SUFFIX}"
    if not force and (public.exists() or secret.exists()):
        raise _usage(f"{secret if secret.exists() else public} exists; --force replaces it")
    allowed = _allowed_path(allow_in, granted, name, force) if allow_in is not None else None
    try:
        directory.mkdir(parents=True, exist_ok=True)
        import zmq.auth  # here: the other commands start without zmq

        zmq.auth.create_certificates(directory, name)
        secret.chmod(0o600)  # pyzmq writes it with the umask's mode
    except OSError as exc:
        raise _usage(f"cannot write keys into {directory}: {exc.strerror or exc}") from None
    record: dict[str, object] = {"public": str(public), "secret": str(secret)}
    lines = [f"wrote {public} (public) and {secret} (secret: it stays with its owner)"]
    if allowed is not None and allow_in is not None:
        record.update(_allow(public, allowed, allow_in, directory, lines))
        record["role"] = granted.label
    emit(settings, record, "\n".join(lines))


# typer keeps a docstring's line breaks; help reads better with one line per paragraph
keys_app.command("new", help="\n\n".join(
    " ".join(p.split()) for p in inspect.cleandoc(new.__doc__ or "").split("\n\n")))(new)


def _allowed_path(keys_dir: Path, role: Role, name: str, force: bool) -> Path:
    """Where the public key goes in the allow-list; a name has one role only."""
    clients = keys_dir / CLIENTS_DIR
    for other in Role:
        existing = clients / other.label / f"{name}{PUBLIC_SUFFIX}"
        if existing.exists() and not force:
            raise _usage(f"{existing} exists: {name} is in the allow-list as {other.label} "
                         "already; --force replaces it")
    return clients / role.label / f"{name}{PUBLIC_SUFFIX}"


def _allow(public: Path, allowed: Path, keys_dir: Path, directory: Path,
           lines: list[str]) -> dict[str, object]:
    """Copy the public key into the allow-list (dropping the name from other roles) and
    the service's public key beside the client's key."""
    record: dict[str, object] = {}
    try:
        for other in (keys_dir / CLIENTS_DIR).glob(f"*/{public.name}"):
            other.unlink()  # --force: one role per name
        allowed.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(public, allowed)
        lines.append(f"allowed as {allowed.parent.name}: {allowed} "
                     "(restart cnc-service to admit it)")
        record["allowed"] = str(allowed)
        server = keys_dir / SERVER_KEY_FILE
        beside = directory / SERVER_KEY_FILE
        if server.is_file() and server.resolve() != beside.resolve():
            shutil.copyfile(server, beside)
            lines.append(f"copied the service's public key to {beside}")
            record["server_key"] = str(beside)
        elif not server.is_file():
            lines.append(f"{server} does not exist yet: make it with "
                         f"`cnc keys new server --dir {keys_dir}` and copy it to {beside}")
    except OSError as exc:
        raise _usage(f"cannot write into {keys_dir}: {exc.strerror or exc}") from None
    return record
