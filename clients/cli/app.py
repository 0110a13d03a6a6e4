"""What every ``cnc`` command shares: the typer app, the consoles, the global options,
output (``emit``) and errors to exit codes (``fail``).

The command modules (``cli_objects``, ``cli_machine``, ``cli_plot``) import this module
and register their commands on ``app``; the entry module ``cli`` imports them. Nothing
here imports a command module, so the package reads top-down without an import circle.

Exit codes: 0 done; 1 the service answered with an ADS error; 2 bad usage, or a value the
client refused before sending it (a key file that cannot be read, too); 3 the service did
not answer (timeout, not reachable) or would not let this client in (its CURVE key
refused).
"""

from __future__ import annotations

import contextlib
import inspect
import json
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING, Any, NoReturn, TypeVar

import typer
import typer.core

from ..errors import (
    AdsError,
    AdsTimeoutError,
    AuthenticationError,
    ClientValueError,
    NoReplyError,
    ServiceFullError,
)
from ..units import tidy
from .terminal import Terminal

if TYPE_CHECKING:  # imported where a command connects: cnc --help needs no zmq
    from ..blocking import Client
    from ..client import AsyncClient

T = TypeVar("T")

EXIT_ADS_ERROR = 1
EXIT_USAGE = 2
EXIT_UNREACHABLE = 3

# rich_markup_mode=None: click's plain help, without rich (docs/design-notes.md, "A quick
# cnc"): it starts sooner, and it shows a flag as a flag (--wait, not --wait <bool>).
app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    rich_markup_mode=None,
    help="Read, write, browse and watch the objects of a cnc-objects service; run and "
         "check NC programs.",
)
out = Terminal(stderr=False)
err = Terminal(stderr=True)


class UsageCommand(typer.core.TyperCommand):
    """A command whose usage line names its arguments as a man page does: ``cnc run
    [OPTIONS] PROGRAM``, an optional one in brackets (typer writes ``{PROGRAM}``, and
    ``{name}`` for an argument without a metavar)."""

    def collect_usage_pieces(self, ctx: typer.Context) -> list[str]:  # type: ignore[override]
        pieces = [self.options_metavar] if self.options_metavar else []
        for param in self.get_params(ctx):
            if param.param_type_name == "argument":
                pieces.append(_argument_usage(param))
            else:
                pieces.extend(param.get_usage_pieces(ctx))
        return pieces


def _argument_usage(param: Any) -> str:
    """``PROGRAM``, ``[PATTERN]``, ``NAME...``: the metavar, else the name in capitals."""
    name: str = param.metavar or (param.name or "").upper()
    if param.metavar is None and param.nargs != 1:
        name += "..."
    if not param.required and not name.startswith("["):
        name = f"[{name}]"
    return name


def use_usage_command(typer_app: typer.Typer) -> None:
    """Every command of ``typer_app`` and of its sub-apps (``cnc tool set``) prints its
    usage line as ``UsageCommand`` does, whichever module registered it and how; the
    entry module calls this once every command module is imported."""
    for info in typer_app.registered_commands:
        if info.cls in (None, typer.core.TyperCommand):  # not a class of its own
            info.cls = UsageCommand
    for group in typer_app.registered_groups:
        if group.typer_instance is not None:
            use_usage_command(group.typer_instance)


def command(*args: Any, **kwargs: Any) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """``app.command`` with the function's docstring as help, each paragraph on one line:
    typer keeps a docstring's line breaks, which breaks lines mid-sentence in --help.
    The first paragraph is the line of the command list."""

    def register(function: Callable[..., Any]) -> Callable[..., Any]:
        text = inspect.cleandoc(function.__doc__ or "")
        help_text = "\n\n".join(" ".join(p.split()) for p in text.split("\n\n"))
        return app.command(*args, help=help_text, **kwargs)(function)

    return register


class Settings:
    """Global options, shared by every command."""

    def __init__(self, endpoint: str, as_json: bool, timeout_s: float,
                 key_file: str | None = None, server_key: str | None = None) -> None:
        self.endpoint = endpoint
        self.as_json = as_json
        self.timeout_s = timeout_s
        self.key_file = key_file  # CURVE: this client's secret key file (--key, CNC_KEY)
        self.server_key = server_key  # the service's public key (--server-key, CNC_SERVER_KEY)

    def client(self) -> Client:
        """A blocking client for one command (``ClientValueError`` for a bad key file)."""
        from ..blocking import Client

        return Client(self.endpoint, timeout_s=self.timeout_s, key_file=self.key_file,
                      server_key=self.server_key)

    def async_client(self) -> AsyncClient:
        """An asyncio client for one command (``ClientValueError`` for a bad key file)."""
        from ..client import AsyncClient

        return AsyncClient(self.endpoint, timeout_s=self.timeout_s, key_file=self.key_file,
                           server_key=self.server_key)

    @contextlib.contextmanager
    def session(self, request: str | None = None) -> Iterator[Client]:
        """A blocking client for one command; a request without reply is told as no
        reply to ``request`` (what the user asked for), not to the ADS command that
        happened to be unanswered first."""
        try:
            with self.client() as c:
                yield c
        except NoReplyError as exc:
            if request is None:
                raise
            raise exc.asking(request) from None

    def call(self, operation: Callable[[Client], T], request: str | None = None) -> T:
        """``operation`` on a client of its own (``session``); an error ends the command
        (``fail``)."""
        try:
            with self.session(request) as c:
                return operation(c)
        except (AdsError, ClientValueError) as exc:
            fail(exc)


def say_error(text: str) -> None:
    """One ``error: ...`` line on stderr, printed as is (names hold brackets: gpCh[0])."""
    err.print(f"error: {text}", markup=False, emoji=False)


def fail(exc: Exception) -> NoReturn:
    """End the command for ``exc``: one line on stderr and the exit code of its kind."""
    say_error(str(exc))
    if isinstance(exc, (AdsTimeoutError, AuthenticationError, ServiceFullError)):
        raise typer.Exit(EXIT_UNREACHABLE)
    if isinstance(exc, AdsError):
        raise typer.Exit(EXIT_ADS_ERROR)
    raise typer.Exit(EXIT_USAGE)  # refused by the client: nothing was sent


def emit(settings: Settings, record: dict[str, Any], human: str) -> None:
    """Print one result: ``record`` as a JSON line with ``--json``, else ``human``. Floats
    are rounded to the resolution their key's unit names (``positions_mm``), others lose
    their float noise (clients/units.py)."""
    if settings.as_json:
        out.print(json.dumps(tidy(record), default=str), markup=False, emoji=False)
    else:
        out.print(human, markup=False, emoji=False)
