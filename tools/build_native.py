"""Compile the kernel's per-block hot path with mypyc (issue 37, short blocks).

The modules in ``NATIVE_MODULES`` (path preparation, look-ahead planner, interpolator,
contour look-ahead: the typed, mypy-strict code every block and cycle runs through) are
compiled to C extensions with mypyc, which comes with mypy, and gcc. They go to
``build/native/lib`` with a manifest of the sources' SHA-256; the package's import hook
(``cnc_objects/_native.py``) loads them only while every source is unchanged, otherwise
the pure-Python modules run: both give the same results bit for bit
(``tests/service/kernel/test_native_path.py``).

``make run`` and ``make test`` run this after installing. It never fails the build:
without mypyc, a C compiler or Python's headers it prints a warning and the service runs
pure Python (slower on programs of short blocks).

    python tools/build_native.py          # build (skipped when up to date)
    python tools/build_native.py --force  # build again
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "build" / "native"
LIB = OUT / "lib"
MANIFEST = LIB / "manifest.json"
#: No fused multiply-add: a * b + c stays two roundings as in Python (gcc contracts by
#: default where the target has FMA, e.g. aarch64), so the results are the same bit for bit.
CFLAGS = "-ffp-contract=off"

#: The compiled modules (all or none are loaded: compiled modules of one group call each
#: other natively). Each must pass mypy strict, which mypyc relies on.
NATIVE_MODULES = (
    "cnc_objects.service.kernel.path.geometry",
    "cnc_objects.service.kernel.path.limits",
    "cnc_objects.service.kernel.path.profile",
    "cnc_objects.service.kernel.path.segments",
    "cnc_objects.service.kernel.path.compensation",
    "cnc_objects.service.kernel.path.planner",
    "cnc_objects.service.kernel.path.interpolator",
    "cnc_objects.service.kernel.path.executor",
    "cnc_objects.service.kernel.contour_lookahead",
)

#: subpackage -> the repository folder it comes from (pyproject's package-dir)
FOLDERS = {"protocol": "protocol", "objects": "objects", "service": "service",
           "clients": "clients"}


def source_of(module: str, root: Path = ROOT) -> Path:
    """The repository file of ``module`` (a name under ``cnc_objects``)."""
    parts = module.split(".")[1:]
    folder = FOLDERS.get(parts[0])
    base = root / folder if folder else root / "cnc_objects" / parts[0]
    return base.joinpath(*parts[1:]).with_suffix(".py")


def digest(path: Path) -> str:
    """SHA-256 of a file's bytes."""
    return hashlib.sha256(path.read_bytes()).hexdigest()


def up_to_date() -> bool:
    """The manifest matches the sources and this Python."""
    try:
        manifest = json.loads(MANIFEST.read_text())
    except (OSError, ValueError):
        return False
    modules = manifest.get("modules", {})
    return (manifest.get("cache_tag") == sys.implementation.cache_tag
            and manifest.get("cflags") == CFLAGS
            and set(modules) == set(NATIVE_MODULES)
            and all(modules[m]["sha256"] == digest(source_of(m)) for m in NATIVE_MODULES))


def _warn(reason: str) -> int:
    print(f"warning: the kernel's hot path is not compiled ({reason}); the service runs "
          "pure Python, with the same results, slower on programs of short blocks "
          "(docs/design-notes.md, 'Short blocks')", file=sys.stderr)
    return 0


def build() -> int:
    """Compile into a scratch copy of the package, then install into ``LIB``."""
    try:
        import mypyc  # noqa: F401  (comes with mypy)
    except ImportError:
        return _warn("mypyc is not installed: pip install mypy")
    if shutil.which(os.environ.get("CC", "gcc")) is None and shutil.which("cc") is None:
        return _warn("no C compiler (gcc or cc)")
    sys.path.insert(0, str(ROOT))
    from tools.typecheck import link_tree  # the package laid out as installed

    tree = link_tree()
    with tempfile.TemporaryDirectory(prefix="cnc-native-") as scratch:
        src = Path(scratch) / "src"
        shutil.copytree(tree / "cnc_objects", src / "cnc_objects",
                        ignore=shutil.ignore_patterns("__pycache__", "*.so"))
        # mypy's settings for the package (pydantic's plugin types the configuration)
        (src / "mypy.ini").write_text(
            "[mypy]\npython_version = 3.11\nplugins = pydantic.mypy\n"
            "[mypy-amqtt.*,pyads.*,msgpack.*]\nignore_missing_imports = True\n")
        files = [str(_in_tree(m)) for m in NATIVE_MODULES]
        lib = Path(scratch) / "lib"
        script = (
            "import sys\n"
            "from setuptools import setup\n"
            "from mypyc.build import mypycify\n"
            "setup(name='cnc_native', ext_modules=mypycify(sys.argv[1:], opt_level='3'),\n"
            f"      script_args=['build_ext', '--build-lib', {str(lib)!r},\n"
            f"                   '--build-temp', {str(Path(scratch) / 'tmp')!r}])\n"
        )
        env = dict(os.environ, CFLAGS=f"{os.environ.get('CFLAGS', '')} {CFLAGS}".strip())
        done = subprocess.run([sys.executable, "-c", script, *files], cwd=src, env=env,
                              capture_output=True, text=True)
        if done.returncode != 0:
            tail = (done.stderr or done.stdout).strip().splitlines()[-3:]
            return _warn("mypyc failed: " + " | ".join(tail))
        built = sorted(lib.rglob("*.so"))
        group = [p for p in built if p.parent == lib]
        modules = {}
        for m in NATIVE_MODULES:
            found = [p for p in built if p.name.split(".")[0] == m.rsplit(".", 1)[1]
                     and p.parent == lib.joinpath(*m.split(".")[:-1])]
            if len(found) != 1:
                return _warn(f"mypyc built no extension for {m}")
            modules[m] = {"so": str(found[0].relative_to(lib)),
                          "sha256": digest(source_of(m))}
        if LIB.exists():
            shutil.rmtree(LIB)
        shutil.copytree(lib, LIB)
        MANIFEST.write_text(json.dumps({
            "cache_tag": sys.implementation.cache_tag,
            "cflags": CFLAGS,
            "group": [p.name.split(".")[0] for p in group],
            "group_files": [p.name for p in group],
            "modules": modules,
        }, indent=1))
    print(f"compiled the kernel's hot path ({len(NATIVE_MODULES)} modules) into {LIB}")
    return 0


def _in_tree(module: str) -> Path:
    """``module``'s file relative to the scratch copy's root."""
    return Path(*module.split(".")).with_suffix(".py")


def main() -> int:
    """Build unless up to date (``--force``: always)."""
    if "--force" not in sys.argv and up_to_date():
        return 0
    try:
        return build()
    except Exception as exc:  # whatever goes wrong, the pure-Python kernel still runs
        return _warn(f"the build failed: {exc!r}")


if __name__ == "__main__":
    sys.exit(main())
