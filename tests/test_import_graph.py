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

import ast
import functools
from collections.abc import Iterator
from dataclasses import dataclass
from graphlib import CycleError, TopologicalSorter
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parent.parent
ROOT_PACKAGE = "cnc_objects"
# Installed package -> repository folder (pyproject.toml [tool.setuptools.package-dir]).
PACKAGE_FOLDERS = {
    f"{ROOT_PACKAGE}.protocol": REPO_ROOT / "protocol",
    f"{ROOT_PACKAGE}.objects": REPO_ROOT / "objects",
    f"{ROOT_PACKAGE}.service": REPO_ROOT / "service",
    f"{ROOT_PACKAGE}.clients": REPO_ROOT / "clients",
}

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


@dataclass(frozen=True)
class Edge:
    """One import statement: ``importer`` names ``imported`` at ``line``."""

    importer: str
    imported: str
    line: int


@dataclass(frozen=True)
class ModuleSource:
    """One of our modules: its dotted name, file and whether it is a package."""

    name: str
    path: Path
    is_package: bool

    @property
    def package(self) -> str:
        """The package a relative import in this module is resolved against."""
        return self.name if self.is_package else self.name.rpartition(".")[0]


def _within(name: str, package: str) -> bool:
    """True if module ``name`` is ``package`` or lies below it."""
    return name == package or name.startswith(package + ".")


@functools.cache
def our_modules() -> dict[str, ModuleSource]:
    """Every ``.py`` file of the four packages, by installed dotted name."""
    modules: dict[str, ModuleSource] = {}
    for package, folder in PACKAGE_FOLDERS.items():
        for path in sorted(folder.rglob("*.py")):
            parts = path.relative_to(folder).with_suffix("").parts
            is_package = parts[-1] == "__init__"
            if is_package:
                parts = parts[:-1]
            name = ".".join((package, *parts))
            modules[name] = ModuleSource(name, path, is_package)
    return modules


def _resolve(base: str, names: list[str], modules: dict[str, ModuleSource]) -> Iterator[str]:
    """The modules that ``from base import names`` loads: submodules or ``base`` itself."""
    for name in names:
        submodule = f"{base}.{name}"
        if submodule in modules:
            yield submodule
        elif base in modules:
            yield base
        else:  # beside the four folders (the cnc_objects root): no module of the graph
            yield base


def _imports_of(module: ModuleSource,
                modules: dict[str, ModuleSource]) -> Iterator[tuple[str, int]]:
    """``(imported name, line)`` for every import statement anywhere in ``module``.

    Names of our own modules are resolved to a module in ``modules``; other names are
    yielded as written (third-party and stdlib), for the library rules.
    """
    tree = ast.parse(module.path.read_text(encoding="utf-8"), filename=str(module.path))
    for node in ast.walk(tree):
        match node:
            case ast.Import(names=aliases):
                for alias in aliases:
                    yield _longest_known_prefix(alias.name, modules), node.lineno
            case ast.ImportFrom(level=0, module=base, names=aliases):
                assert base is not None
                if _within(base, ROOT_PACKAGE):
                    for target in _resolve(base, [a.name for a in aliases], modules):
                        yield target, node.lineno
                else:
                    yield base, node.lineno
            case ast.ImportFrom(level=level, module=base, names=aliases):
                anchor = module.package.split(".")
                if level - 1 >= len(anchor):
                    raise AssertionError(
                        f"{module.path}:{node.lineno}: relative import above the root")
                anchor = anchor[: len(anchor) - (level - 1)]
                target_base = ".".join(anchor + ([base] if base else []))
                for target in _resolve(target_base, [a.name for a in aliases], modules):
                    yield target, node.lineno


def _longest_known_prefix(name: str, modules: dict[str, ModuleSource]) -> str:
    """``import a.b.c`` loads the deepest of ``a.b.c``, ``a.b``, ``a`` that is ours."""
    parts = name.split(".")
    for end in range(len(parts), 0, -1):
        candidate = ".".join(parts[:end])
        if candidate in modules:
            return candidate
    return name


@functools.cache
def import_edges() -> tuple[Edge, ...]:
    """Every import of every module of ours, including third-party and stdlib names."""
    modules = our_modules()
    return tuple(
        Edge(module.name, imported, line)
        for module in modules.values()
        for imported, line in _imports_of(module, modules)
        if imported != module.name
    )


def internal_graph() -> dict[str, dict[str, int]]:
    """``importer -> {imported: first line}`` over our own modules only."""
    modules = our_modules()
    graph: dict[str, dict[str, int]] = {name: {} for name in modules}
    for edge in import_edges():
        if edge.imported in modules:
            graph[edge.importer].setdefault(edge.imported, edge.line)
    return graph


def import_cycles(graph: dict[str, dict[str, int]]) -> list[list[str]]:
    """Circles of ``graph`` as import paths ``[a, b, ..., a]`` (a imports b ...).

    ``graphlib`` finds one circle at a time; its closing import is then left out, so the
    next search shows the next circle, until the graph sorts: every module of a circle
    appears in at least one reported path.
    """
    # graphlib wants node -> predecessors: a module's imports come before it
    remaining = {name: set(imported) for name, imported in graph.items()}
    cycles = []
    while True:
        try:
            TopologicalSorter(remaining).prepare()
        except CycleError as error:
            # each node of graphlib's path comes before the next: the next imports it
            cycle = list(reversed(error.args[1]))
            cycles.append(cycle)
            remaining[cycle[-2]].discard(cycle[-1])
        else:
            return cycles


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
