"""Load the compiled kernel hot path when it matches the sources (issue 37).

``tools/build_native.py`` (run by ``make run`` and ``make test``) compiles a few typed
kernel modules with mypyc into ``build/native/lib`` and writes a manifest with each
source's SHA-256. This finder, first on ``sys.meta_path``, hands out those extensions
only while every listed source is unchanged (checked once, at the first import of one of
them); otherwise, or with ``CNC_NATIVE=0`` in the environment, or where nothing was
built (an installed wheel, no compiler), the pure-Python modules are imported as usual.
Both give the same results bit for bit: the compiled code is the same source, with the
same float operations (``tests/service/kernel/test_native_path.py``).
"""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import importlib.util
import json
import logging
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from types import ModuleType

log = logging.getLogger(__name__)

ROOT = Path(__file__).resolve().parent.parent
LIB = ROOT / "build" / "native" / "lib"
#: subpackage -> the repository folder it comes from (pyproject's package-dir)
_FOLDERS = {"protocol": "protocol", "objects": "objects", "service": "service",
            "clients": "clients"}


def _source_of(module: str) -> Path:
    parts = module.split(".")[1:]
    folder = _FOLDERS.get(parts[0])
    base = ROOT / folder if folder else ROOT / "cnc_objects" / parts[0]
    return base.joinpath(*parts[1:]).with_suffix(".py")


class NativeFinder(importlib.abc.MetaPathFinder):
    """Finds the compiled modules of the manifest (and their shared mypyc library)."""

    def __init__(self, manifest: dict[str, object]) -> None:
        modules = manifest.get("modules")
        self.modules: dict[str, dict[str, str]] = modules if isinstance(modules, dict) else {}
        files = manifest.get("group_files")
        self._group = {name.split(".")[0]: name for name in files} if isinstance(
            files, list) else {}
        self._checked: bool | None = None  # None: not yet; then: the sources match

    @property
    def active(self) -> bool:
        """The compiled modules are current (checked once)."""
        if self._checked is None:
            self._checked = self._current()
        return self._checked

    def _current(self) -> bool:
        import hashlib  # here: the package's import (every ``cnc`` start) stays light

        for module, entry in self.modules.items():
            try:
                digest = hashlib.sha256(_source_of(module).read_bytes()).hexdigest()
            except OSError:
                return False
            if digest != entry.get("sha256"):
                log.warning("the compiled kernel hot path is older than %s: running pure "
                            "Python (make run / make test compile it again)", module)
                return False
        return True

    def find_spec(self, fullname: str, path: Sequence[str] | None = None,
                  target: ModuleType | None = None) -> importlib.machinery.ModuleSpec | None:
        """The compiled module's spec, else None (the other finders go on)."""
        entry = self.modules.get(fullname)
        if entry is not None:
            file = LIB / entry["so"]
        elif fullname in self._group:
            file = LIB / self._group[fullname]
        else:
            return None
        if not self.active or not file.exists():
            return None
        loader = importlib.machinery.ExtensionFileLoader(fullname, str(file))
        return importlib.util.spec_from_file_location(fullname, file, loader=loader)


def load_manifest() -> dict[str, object] | None:
    """The build's manifest, when one for this Python exists."""
    try:
        manifest = json.loads((LIB / "manifest.json").read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(manifest, dict) or manifest.get("cache_tag") != sys.implementation.cache_tag:
        return None
    return manifest


def install() -> NativeFinder | None:
    """Put the finder first on ``sys.meta_path`` when a manifest for this Python exists
    and ``CNC_NATIVE`` is not 0."""
    if os.environ.get("CNC_NATIVE", "1") == "0":
        return None
    manifest = load_manifest()
    if manifest is None:
        return None
    finder = NativeFinder(manifest)
    sys.meta_path.insert(0, finder)
    return finder


def compiled(module: ModuleType) -> bool:
    """``module`` was loaded from a compiled extension."""
    return isinstance(getattr(module, "__loader__", None), importlib.machinery.ExtensionFileLoader)
