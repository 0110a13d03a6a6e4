"""A guard for the decoder's fast constructors (``nc/construct.py`` builds Blocks as
mutable twins and swaps their ``__class__``): the decoder's tests pass with the twins
off too, and every example program decodes to the same blocks (or the same error) both
ways. An edit that breaks one of the two paths fails here."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from cnc_objects.service.kernel.nc.construct import FAST, PLAIN_CONSTRUCTORS_ENV

REPO = Path(__file__).resolve().parents[4]
NC_TESTS = Path(__file__).resolve().parent
EXAMPLES = REPO / "docs" / "examples"
PROGRAMS = sorted([*EXAMPLES.glob("*.nc"), *(EXAMPLES / "cycles").glob("*.nc"),
                   *(EXAMPLES / "hsc").glob("*.nc"), REPO / "tests" / "data" / "isg-syntax-showcase.nc"])

# Decodes each program given on the command line with every example file as the store
# (cycles, subprograms) and prints, per program, a digest of its blocks' repr or its error.
_DECODE_ALL = """
import hashlib, json, sys
from pathlib import Path
from cnc_objects.service.kernel.nc import Decoder, NcError
from cnc_objects.service.kernel.nc import construct

paths = [Path(p) for p in sys.argv[1:]]
store = {p.name: p.read_text(encoding="utf-8", errors="replace")
         for p in Path(sys.argv[1]).parents[0].rglob("*") if p.is_file()}
store.update({p.name: p.read_text(encoding="utf-8", errors="replace") for p in paths})

def load(name):
    return store[name]

out = {"fast": construct.FAST}
for path in paths:
    decoder = Decoder(store[path.name], path.name, axes=("X", "Y", "Z"), loader=load,
                      tools={1: 1.0, 2: 2.5, 3: 5.0, 8: 4.0, 9: 3.0})
    blocks = []
    try:
        for block in decoder.blocks():
            blocks.append(block)
            if len(blocks) > 200000:
                break
        ending = "end"
    except NcError as exc:
        ending = repr(exc)
    out[path.name] = [len(blocks), hashlib.sha256(repr(blocks).encode()).hexdigest(), ending]
print(json.dumps(out))
"""


def _env(plain: bool) -> dict[str, str]:
    env = dict(os.environ)
    env[PLAIN_CONSTRUCTORS_ENV] = "1" if plain else "0"
    return env


def _decode_all(plain: bool) -> dict[str, object]:
    done = subprocess.run([sys.executable, "-c", _DECODE_ALL, *map(str, PROGRAMS)],
                          capture_output=True, text=True, env=_env(plain), cwd=REPO,
                          timeout=300, check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    result: dict[str, object] = json.loads(done.stdout)
    return result


def test_this_interpreter_uses_the_fast_constructors() -> None:
    """Otherwise the comparison below would compare the plain path with itself."""
    assert FAST


def test_example_programs_decode_to_the_same_blocks_with_and_without_the_twins() -> None:
    fast, plain = _decode_all(plain=False), _decode_all(plain=True)
    assert fast.pop("fast") is True and plain.pop("fast") is False
    assert len(fast) == len(PROGRAMS) and sum(n for n, _, _ in fast.values()) > 1000
    assert fast == plain


@pytest.mark.soak  # the whole decoder suite again (about 90 s): `make soak`
def test_the_decoder_tests_pass_with_the_plain_constructors() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider", str(NC_TESTS),
         "--deselect", f"{Path(__file__).relative_to(REPO)}"],
        capture_output=True, text=True, env=_env(plain=True), cwd=REPO, timeout=600,
        check=False)
    assert done.returncode == 0, done.stdout[-3000:]
    assert " passed" in done.stdout.splitlines()[-1]
