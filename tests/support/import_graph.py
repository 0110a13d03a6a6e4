"""The import graph of our four packages, built from the source with ast (never by importing)."""

from __future__ import annotations

import ast
import functools
from collections.abc import Iterator
from dataclasses import dataclass
from graphlib import CycleError, TopologicalSorter
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]


ROOT_PACKAGE = "cnc_objects"


# Installed package -> repository folder (pyproject.toml [tool.setuptools.package-dir]).
PACKAGE_FOLDERS = {
    f"{ROOT_PACKAGE}.protocol": REPO_ROOT / "protocol",
    f"{ROOT_PACKAGE}.objects": REPO_ROOT / "objects",
    f"{ROOT_PACKAGE}.service": REPO_ROOT / "service",
    f"{ROOT_PACKAGE}.clients": REPO_ROOT / "clients",
}


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
