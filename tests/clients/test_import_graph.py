"""The ``cnc`` modules read top-down: the command modules import the shared ``cli.app``,
the entry package ``cli`` imports the command modules, and only its ``__main__`` imports it.
(The graph comes from ``tests/test_import_graph.py``: ``ast``, nothing is executed.)"""

from __future__ import annotations

from tests.support.import_graph import import_cycles, internal_graph

CLIENTS = "cnc_objects.clients"
COMMAND_MODULES = {f"{CLIENTS}.cli.objects", f"{CLIENTS}.cli.machine", f"{CLIENTS}.cli.plot"}


def clients_graph() -> dict[str, dict[str, int]]:
    """``importer -> {imported: line}`` within ``cnc_objects.clients`` only."""
    return {
        name: {m: line for m, line in imports.items() if m.startswith(CLIENTS + ".")}
        for name, imports in internal_graph().items()
        if name.startswith(CLIENTS + ".")
    }


def test_the_clients_modules_have_no_import_circle() -> None:
    assert import_cycles(clients_graph()) == []


def test_the_entry_module_imports_the_commands_and_nothing_imports_it() -> None:
    graph = clients_graph()
    assert COMMAND_MODULES <= set(graph[f"{CLIENTS}.cli"])
    importers = [name for name, imports in graph.items() if f"{CLIENTS}.cli" in imports]
    assert importers == [f"{CLIENTS}.cli.__main__"]  # python -m cnc_objects.clients.cli
    for module in COMMAND_MODULES:  # each takes what it shares from below, not from cli
        assert f"{CLIENTS}.cli.app" in graph[module], module
