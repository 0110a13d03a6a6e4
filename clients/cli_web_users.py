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

import typer

from .cli_app import EXIT_USAGE, app, say_error
from .web.users import DEFAULT_USERS_FILE, WebRole, WebUsers, load_users, save_users

web_users_app = typer.Typer(
    add_completion=False, no_args_is_help=True,
    help="Set the passwords with which browsers sign in to cnc-web, one per role.",
)
app.add_typer(web_users_app, name="web-users")

FileOption = typer.Option(DEFAULT_USERS_FILE, "--file", metavar="FILE",
                          help=f"The web users file (default {DEFAULT_USERS_FILE}).")


def _role(name: str) -> WebRole:
    try:
        return WebRole.parse(name)
    except ValueError as exc:
        say_error(str(exc))
        raise typer.Exit(EXIT_USAGE) from None


def _load(path: Path) -> WebUsers:
    if not path.exists():
        return WebUsers()
    try:
        return load_users(path)
    except ValueError as exc:
        say_error(str(exc))
        raise typer.Exit(EXIT_USAGE) from None


def _password(role: WebRole) -> str:
    if not sys.stdin.isatty():
        return sys.stdin.readline().rstrip("\r\n")
    return str(typer.prompt(f"password for role {role.label}", hide_input=True,
                            confirmation_prompt=True))


@web_users_app.command("set")
def set_password(role: str = typer.Argument(..., help="monitor, operator or admin."),
                 file: Path = FileOption) -> None:
    """Set (or change) the password of ROLE."""
    chosen = _role(role)
    users = _load(file)
    try:
        users.set_password(chosen, _password(chosen))
    except ValueError as exc:
        say_error(str(exc))
        raise typer.Exit(EXIT_USAGE) from None
    save_users(file, users)
    print(f"role {chosen.label} can sign in to cnc-web ({file}; a running cnc-web ends the "
          "sessions of its old password at once)")


@web_users_app.command("remove")
def remove(role: str = typer.Argument(..., help="monitor, operator or admin."),
           file: Path = FileOption) -> None:
    """Remove the password of ROLE: it can no longer sign in."""
    chosen = _role(role)
    users = _load(file)
    if not users.remove(chosen):
        say_error(f"role {chosen.label} has no password in {file}")
        raise typer.Exit(1)
    save_users(file, users)
    print(f"role {chosen.label} can no longer sign in ({file}; a running cnc-web ends its "
          "sessions at once)")


@web_users_app.command("list")
def list_roles(file: Path = FileOption) -> None:
    """The roles that can sign in."""
    users = _load(file)
    print(" ".join(r.label for r in users.roles) or f"no role can sign in ({file})")
