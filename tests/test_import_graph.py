"""The import graph of our four packages: no circles, and the layers of docs/architecture.md.

The graph is built from the source with the stdlib ``ast``, never by importing, so a
circle is found even where it is dodged at run time by an import inside a function
(such an import still makes the two modules depend on each other) or by an import under
``TYPE_CHECKING``. Every import statement counts wherever it stands: module level,
function body, class body, ``if`` or ``try`` block.

Module names are the installed ones: the repository folders ``protocol/ objects/
service/ clients/`` are ``cnc_objects.protocol``, ``.objects``, ``.service`` and
``.clients`` (setuptools ``package-dir``). Relative imports are resolved against the
importing module's package; ``from package import name`` is an edge to the submodule
``package.name`` when that file exists and to the package's ``__init__`` otherwise.
Importing a submodule also runs the ``__init__`` of its packages first; that implicit
step is not an edge (every package would then be in a circle with the submodules its
``__init__`` re-exports), so a package ``__init__`` counts only where it is named.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.support.import_graph import (
    ROOT_PACKAGE,
    ModuleSource,
    _imports_of,
    _within,
    import_cycles,
    import_edges,
    internal_graph,
    our_modules,
)

PROTOCOL = f"{ROOT_PACKAGE}.protocol"
OBJECTS = f"{ROOT_PACKAGE}.objects"
SERVICE = f"{ROOT_PACKAGE}.service"
CLIENTS = f"{ROOT_PACKAGE}.clients"
KERNEL = f"{SERVICE}.kernel"
# The one module outside the kernel that the kernel may read: the machine's
# configuration (not the front ends', the keys' or the limits', nor the loading). The
# server, dispatcher, bindings, notifications and entry point are above the kernel.
KERNEL_MAY_IMPORT_FROM_SERVICE = (KERNEL, f"{SERVICE}.machine_config")
# Wire libraries the kernel must not know (docs/architecture.md: "knows nothing of sockets,
# msgpack").
KERNEL_FORBIDDEN_LIBRARIES = ("zmq", "msgpack")
ADS_FRONT_END = f"{SERVICE}.ads"
ZMQ_FRONT_END = (f"{SERVICE}.server", f"{SERVICE}.zmq_connections")
STORAGE = f"{SERVICE}.storage"
# What the service keeps on disk knows the kernel's types it stores and the machine's
# configuration, never a front end, the dispatcher or the bindings.
STORAGE_MAY_IMPORT = (STORAGE, KERNEL, f"{SERVICE}.machine_config", f"{SERVICE}.log_throttle",
                      OBJECTS, PROTOCOL)






















def _short(name: str) -> str:
    return name.removeprefix(ROOT_PACKAGE + ".")


def _describe(cycle: list[str], graph: dict[str, dict[str, int]]) -> str:
    """``a (line 12) -> b (line 30) -> a``: each module with the line of its import."""
    hops = [f"{_short(a)} (line {graph[a][b]})" for a, b in zip(cycle, cycle[1:])]
    return " -> ".join([*hops, _short(cycle[-1])])


def test_the_graph_resolves_the_imports_of_the_tree() -> None:
    """The builder on imports known to exist in the tree."""
    edges = {(edge.importer, edge.imported) for edge in import_edges()}
    nc = f"{KERNEL}.nc"
    assert len(our_modules()) > 100
    # relative, into a subpackage: a submodule named in "from .cycles.registry import"
    assert (f"{nc}.cycle_run", f"{nc}.cycles.registry") in edges
    # relative, two levels up (nc/cycles -> nc)
    assert (f"{nc}.cycles.positioning", f"{nc}.literals") in edges
    # "from .nc import Decoder": the package __init__
    assert any(_within(i, KERNEL) and j == nc for i, j in edges)
    # absolute cnc_objects imports, and third-party names kept as written
    assert any(_within(i, KERNEL) and _within(j, PROTOCOL) for i, j in edges)
    assert any(_within(i, CLIENTS) and _within(j, PROTOCOL) for i, j in edges)
    assert (f"{nc}.cycles.fitting", "numpy") in edges


def test_imports_inside_functions_and_type_checking_blocks_count(tmp_path: Path) -> None:
    """An import dodged into a function or under TYPE_CHECKING is still an edge."""
    source = tmp_path / "runner.py"
    source.write_text(
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n"
        "    from .decoder import Decoder\n"
        "def run():\n"
        "    from . import frames\n"
        "    import cnc_objects.pkg.sub.deep\n",
        encoding="utf-8",
    )
    names = ("cnc_objects.pkg", "cnc_objects.pkg.decoder", "cnc_objects.pkg.frames",
             "cnc_objects.pkg.sub")
    modules = {name: ModuleSource(name, tmp_path, name == "cnc_objects.pkg") for name in names}
    runner = ModuleSource("cnc_objects.pkg.runner", source, False)
    assert sorted(_imports_of(runner, modules)) == [
        ("cnc_objects.pkg.decoder", 3), ("cnc_objects.pkg.frames", 5),
        ("cnc_objects.pkg.sub", 6), ("typing", 1),
    ]


def test_a_circle_is_reported_with_its_path() -> None:
    """The checker itself: a three-module circle beside a clean chain."""
    graph = {"a": {"b": 3}, "b": {"c": 7}, "c": {"a": 9, "d": 1}, "d": {}, "e": {"a": 2}}
    (cycle,) = import_cycles(graph)
    start = cycle.index("a")  # graphlib may start the path at any module of the circle
    assert cycle[start:] + cycle[1:start + 1] == ["a", "b", "c", "a"]
    assert _describe(["a", "b", "c", "a"], graph) == "a (line 3) -> b (line 7) -> c (line 9) -> a"
    assert import_cycles({"a": {"b": 1}, "b": {}}) == []
    # two circles through one module: both are reported
    two = import_cycles({"a": {"b": 1, "c": 2}, "b": {"a": 3}, "c": {"a": 4}})
    assert sorted(frozenset(c) for c in two) == [frozenset("ab"), frozenset("ac")]


@pytest.mark.parametrize("package", [PROTOCOL, OBJECTS, SERVICE, CLIENTS],
                         ids=lambda package: _short(package))
def test_no_import_cycles(package: str) -> None:
    """No module of ``package`` reaches itself through imports, at module level or
    inside functions (one test per package, so a circle names its package)."""
    graph = internal_graph()
    cycles = [cycle for cycle in import_cycles(graph)
              if any(_within(name, package) for name in cycle)]
    assert not cycles, "import cycles (module (line of its import) -> ...):\n" + "\n".join(
        _describe(cycle, graph) for cycle in cycles
    )


def _violations(importers: str, allowed: tuple[str, ...]) -> list[str]:
    """Imports of our modules from below ``importers`` that fall outside ``allowed``."""
    modules = our_modules()
    return sorted(
        f"{edge.importer} (line {edge.line}) imports {edge.imported}"
        for edge in import_edges()
        if _within(edge.importer, importers)
        and edge.imported in modules
        and not any(_within(edge.imported, package) for package in allowed)
    )


@pytest.mark.parametrize(
    ("layer", "allowed"),
    [
        pytest.param(PROTOCOL, (PROTOCOL,), id="protocol-imports-nothing-of-ours"),
        pytest.param(OBJECTS, (OBJECTS, PROTOCOL), id="objects-imports-only-protocol"),
        pytest.param(CLIENTS, (CLIENTS, OBJECTS, PROTOCOL), id="clients-never-import-service"),
        pytest.param(KERNEL, (*KERNEL_MAY_IMPORT_FROM_SERVICE, PROTOCOL),
                     id="kernel-below-server"),
        pytest.param(STORAGE, STORAGE_MAY_IMPORT, id="storage-knows-no-front-end"),
    ],
)
def test_layers_import_only_downward(layer: str, allowed: tuple[str, ...]) -> None:
    """The dependency direction of docs/architecture.md: protocol <- objects <- service,
    clients; the kernel and the storage below the front ends."""
    violations = _violations(layer, allowed)
    assert not violations, f"{layer} may import only {allowed}:\n" + "\n".join(violations)


def test_kernel_knows_no_wire_library() -> None:
    """The kernel imports neither ZeroMQ nor msgpack, anywhere in its modules."""
    violations = sorted(
        f"{edge.importer} (line {edge.line}) imports {edge.imported}"
        for edge in import_edges()
        if _within(edge.importer, KERNEL)
        and any(_within(edge.imported, library) for library in KERNEL_FORBIDDEN_LIBRARIES)
    )
    assert not violations, "\n".join(violations)


def test_the_two_front_ends_do_not_know_each_other() -> None:
    """ZeroMQ and ADS are two front ends over one dispatcher: neither imports the other."""
    pairs = [(ADS_FRONT_END, zmq) for zmq in ZMQ_FRONT_END]
    pairs += [(zmq, ADS_FRONT_END) for zmq in ZMQ_FRONT_END]
    violations = sorted(
        f"{edge.importer} (line {edge.line}) imports {edge.imported}"
        for edge in import_edges()
        for importer, imported in pairs
        if _within(edge.importer, importer) and _within(edge.imported, imported)
    )
    assert not violations, "\n".join(violations)
