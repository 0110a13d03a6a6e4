"""The blocking ``Client`` is generated from ``AsyncClient`` (tools/gen_blocking_client.py):
the file in the tree is what the generator makes, every public async method has its
blocking twin with the same parameters, and a type checker sees them."""

from __future__ import annotations

import inspect
import subprocess
import sys
from pathlib import Path

from cnc_objects.clients import AsyncClient, Client

ROOT = Path(__file__).resolve().parents[2]
GENERATOR = ROOT / "tools" / "gen_blocking_client.py"


def test_blocking_client_is_what_the_generator_writes() -> None:
    done = subprocess.run([sys.executable, str(GENERATOR), "--check"],
                          capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr


def _public_async(cls: type) -> dict[str, inspect.Signature]:
    return {name: inspect.signature(fn) for name, fn in inspect.getmembers(cls)
            if not name.startswith("_")
            and (inspect.iscoroutinefunction(fn) or inspect.isasyncgenfunction(fn))}


def test_every_async_method_has_a_blocking_twin_with_the_same_parameters() -> None:
    async_methods = _public_async(AsyncClient)
    assert {"read", "write", "subscribe", "upload", "run_program"} <= set(async_methods)
    for name, signature in async_methods.items():
        twin = getattr(Client, name, None)
        assert twin is not None, f"Client lacks {name}"
        assert list(inspect.signature(twin).parameters) == list(signature.parameters), name
        assert twin.__doc__ == getattr(AsyncClient, name).__doc__, name


def test_methods_are_declared_in_the_class_body() -> None:
    """Declared, not attached at run time: the class's own namespace has them."""
    assert "read" in vars(Client) and "subscribe" in vars(Client)


def test_a_type_checker_flags_a_misspelt_method_and_a_wrong_argument(tmp_path: Path) -> None:
    sys.path.insert(0, str(GENERATOR.parent))
    try:
        import typecheck
    finally:
        sys.path.pop(0)
    script = tmp_path / "user_script.py"
    script.write_text(
        "from cnc_objects.clients import Client\n"
        "with Client() as c:\n"
        "    c.raed('ch1.mc_active_state_r')\n"
        "    c.read_address('551', 0x121301, 0x10018)\n"
        "    value = c.read('ch1.mc_active_state_r')\n",
        encoding="utf-8",
    )
    out, _err, status = typecheck.run([str(script), "--no-incremental", "--follow-imports=silent",
                                       "--cache-dir", str(tmp_path / "cache")])
    assert status == 1, out
    assert '"Client" has no attribute "raed"' in out
    assert 'Argument 1 to "read_address" of "Client" has incompatible type "str"' in out
