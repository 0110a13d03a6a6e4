"""The compiled hot path gives the pure-Python results bit for bit (issue 37).

``tools/build_native.py`` compiles the path modules with mypyc; ``cnc_objects._native``
loads them while their sources are unchanged. The same short-block programs (a piece of
the look-ahead bench's 0.05 mm spiral, of the CAM finishing program, and arcs under
LA_ON) run on the step clock in two processes, one with ``CNC_NATIVE=0`` (pure Python)
and one with the compiled modules: every cycle's observed values must be the same, to
the last bit of every float (compared as ``repr``, which round-trips floats exactly).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from bench.lookahead_programs import spiral
from bench.programs import cam_finish
from cnc_objects import _native

ROOT = Path(__file__).resolve().parents[3]

_CHILD = """
import sys
from cnc_objects import _native
from cnc_objects.service.kernel.path import interpolator, segments
from tests.support.event_speed import run
text = sys.stdin.read()
print("compiled" if _native.compiled(segments) and _native.compiled(interpolator)
      else "pure")
recording = run(text, False, (), {})
for cycle in sorted(recording.values):
    print(cycle, repr(recording.values[cycle]))
"""


def _cam_piece(blocks: int) -> str:
    lines = cam_finish.program().splitlines()
    return "\n".join([*lines[:blocks], "M30"]) + "\n"


def _spiral_piece(blocks: int) -> str:
    return "\n".join([*spiral(blocks=blocks).text.splitlines()]) + "\n"


ARCS_LA_ON = "G90 G17 F6000\nLA_ON\n" + "".join(
    f"G{2 + k % 2} X{(k + 1) * 0.08:.3f} Y0 I0.04 J0\n" for k in range(150)) + "LA_OFF\nM30\n"

PROGRAMS = {"spiral": _spiral_piece(400), "cam": _cam_piece(500), "arcs-la-on": ARCS_LA_ON}


def _cycles(text: str, native: bool) -> list[str]:
    env = dict(os.environ, CNC_NATIVE="1" if native else "0")
    done = subprocess.run([sys.executable, "-c", _CHILD], input=text, cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0] == ("compiled" if native else "pure"), lines[0]
    return lines[1:]


@pytest.mark.parametrize("name", sorted(PROGRAMS))
def test_compiled_path_equals_pure_python(name: str) -> None:
    """Every cycle of a short-block run: the same values compiled and pure."""
    finder = _native.NativeFinder(_native.load_manifest() or {})
    if not finder.modules or not finder.active:
        pytest.skip("the hot path is not compiled here (no compiler, or sources changed "
                    "since the build): tools/build_native.py")
    pure = _cycles(PROGRAMS[name], native=False)
    compiled = _cycles(PROGRAMS[name], native=True)
    assert len(pure) > 100  # the run reached its end through many cycles
    for a, b in zip(compiled, pure, strict=True):
        assert a == b, f"compiled: {a}\npure:     {b}"


def test_a_changed_source_makes_the_finder_step_aside() -> None:
    """A manifest whose hash is not the source's: nothing compiled is handed out (the
    pure module is imported instead), whatever the build left in ``build/native``."""
    module = "cnc_objects.service.kernel.path.limits"
    finder = _native.NativeFinder({"modules": {module: {
        "so": "cnc_objects/service/kernel/path/limits.so", "sha256": "0" * 64}}})
    assert not finder.active
    assert finder.find_spec(module) is None


def test_without_a_compiler_the_build_warns_and_succeeds(tmp_path: Path) -> None:
    """No C compiler on the PATH: ``tools/build_native.py`` says so and exits 0 (``make
    run`` goes on, the kernel runs pure Python); what was built before stays."""
    manifest = ROOT / "build" / "native" / "lib" / "manifest.json"
    before = manifest.read_bytes() if manifest.exists() else None
    env = {k: v for k, v in os.environ.items() if k != "CC"}
    env["PATH"] = str(tmp_path)  # an empty folder: no gcc, no cc
    done = subprocess.run([sys.executable, "tools/build_native.py", "--force"], cwd=ROOT,
                          env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "warning: the kernel's hot path is not compiled (no C compiler" in done.stderr
    assert (manifest.read_bytes() if manifest.exists() else None) == before
