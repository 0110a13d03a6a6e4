"""``cnc web-users``: the passwords with which browsers sign in to cnc-web (docs/web.md).

    cnc web-users set operator [--file cnc-data/web-users.json]   # asks twice, or reads stdin
    cnc web-users remove monitor
    cnc web-users list

One password per role (monitor, operator, admin), stored as an Argon2 hash in a file
of mode 0600; cnc-web reads it at start. Piped (``echo secret | cnc web-users set
monitor``) the first line of stdin is the password, for scripts and tests.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from .app import EXIT_USAGE, app, say_error

if TYPE_CHECKING:  # imported by the commands that use them (argon2: not on every start)
    from ..web.users import WebRole, WebUsers

DEFAULT_FILE_TEXT = "cnc-data/web-users.json"  # shown in --help; users.DEFAULT_USERS_FILE

web_users_app = typer.Typer(
    add_completion=False, no_args_is_help=True,
    help="Set the passwords with which browsers sign in to cnc-web, one per role.",
)
app.add_typer(web_users_app, name="web-users")

FileOption = typer.Option(None, "--file", metavar="FILE", show_default=False,
                          help=f"The web users file (default {DEFAULT_FILE_TEXT}).")


def _file(path: Path | None) -> Path:
    """The file given, else the users' default file."""
    from ..web.users import DEFAULT_USERS_FILE

    return DEFAULT_USERS_FILE if path is None else path


def _role(name: str) -> WebRole:
    from ..web.users import WebRole

    try:
        return WebRole.parse(name)
    except ValueError as exc:
        say_error(str(exc))
        raise typer.Exit(EXIT_USAGE) from None


def _load(path: Path) -> WebUsers:
    from ..web.users import WebUsers, load_users

    if not path.exists():
        return WebUsers()
    try:
        return load_users(path)
    except ValueError as exc:
        say_error(str(exc))
        raise typer.Exit(EXIT_USAGE) from None


def _save(path: Path, users: WebUsers) -> None:
    from ..web.users import save_users

    save_users(path, users)


def _password(role: WebRole) -> str:
    if not sys.stdin.isatty():
        return sys.stdin.readline().rstrip("\r\n")
    return str(typer.prompt(f"password for role {role.label}", hide_input=True,
                            confirmation_prompt=True))


@web_users_app.command("set")
def set_password(role: str = typer.Argument(..., help="monitor, operator or admin."),
                 file: Path | None = FileOption) -> None:
    """Set (or change) the password of ROLE."""
    chosen, path = _role(role), _file(file)
    users = _load(path)
    try:
        users.set_password(chosen, _password(chosen))
    except ValueError as exc:
        say_error(str(exc))
        raise typer.Exit(EXIT_USAGE) from None
    _save(path, users)
    print(f"role {chosen.label} can sign in to cnc-web ({path}; a running cnc-web ends the "
          "sessions of its old password at once)")


@web_users_app.command("remove")
def remove(role: str = typer.Argument(..., help="monitor, operator or admin."),
           file: Path | None = FileOption) -> None:
    """Remove the password of ROLE: it can no longer sign in."""
    chosen, path = _role(role), _file(file)
    users = _load(path)
    if not users.remove(chosen):
        say_error(f"role {chosen.label} has no password in {path}")
        raise typer.Exit(1)
    _save(path, users)
    print(f"role {chosen.label} can no longer sign in ({path}; a running cnc-web ends its "
          "sessions at once)")


@web_users_app.command("list")
def list_roles(file: Path | None = FileOption) -> None:
    """The roles that can sign in."""
    path = _file(file)
    users = _load(path)
    print(" ".join(r.label for r in users.roles) or f"no role can sign in ({path})")
