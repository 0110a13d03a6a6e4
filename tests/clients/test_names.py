"""The generated object names (clients/names.py, tools/gen_names.py): current with the
catalog, every name a running service serves is reachable through them and gives exactly
that string, and a misspelt name is a type error before anything runs."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path
from typing import Any

from cnc_objects.clients import Client, names

ROOT = Path(__file__).resolve().parents[2]
GENERATOR = ROOT / "tools" / "gen_names.py"
_STEP = re.compile(r"^(?:(ch|ax)(\d+)|([A-Za-z_]\w*)\[(\d+)\]|([A-Za-z_]\w*))$")


def test_names_module_is_what_the_generator_writes() -> None:
    done = subprocess.run([sys.executable, str(GENERATOR), "--check"],
                          capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr


def _through_names(name: str) -> Any:
    """Walk ``name`` through the module: ``ch1.wz[2].radius`` -> names.ch(1).wz(2).radius."""
    here: Any = names
    for position, part in enumerate(name.split(".")):
        m = _STEP.match(part)
        assert m is not None, part
        numbered, number, indexed, index, plain = m.groups()
        if numbered is not None and position < 2:
            here = getattr(here, numbered)(int(number))
        elif indexed is not None:
            here = getattr(here, indexed)(int(index))
        else:
            word = plain if plain is not None else part
            here = getattr(here, word + "_" if word in ("class",) else word)
    return here


def test_every_name_the_service_serves_comes_out_of_the_module(cnc_client: Client) -> None:
    served = [info.name for info in cnc_client.browse("*")]
    assert len(served) > 500  # the whole catalog of the default machine, not a part of it
    wrong = [(name, _through_names(name)) for name in served if _through_names(name) != name]
    assert wrong == []


def test_a_generated_name_reads_on_the_service(cnc_client: Client) -> None:
    """The README's example ("Objects"): the names it shows are those strings and work."""
    assert names.ch(1).mc_active_state_r == "ch1.mc_active_state_r"
    assert names.ch(1).ax(2).manual_increment_w == "ch1.ax2.manual_increment_w"
    assert names.ch(1).wz(3).radius == "ch1.wz[3].radius"
    assert names.alarm_active(1).class_ == "alarm_active[1].class"
    cnc_client.write(names.ch(1).ax(2).manual_increment_w, 1000)
    assert cnc_client.read(names.ch(1).ax(2).manual_increment_w) == 1000
    assert isinstance(cnc_client.read(names.ch(1).wz(3).radius), float)
    assert cnc_client.read(names.ch(1).mc_active_mode_r) == cnc_client.read("ch1.mc_active_mode_r")
    assert cnc_client.read(names.cnc_number_of_channel_r) >= 1


def test_a_misspelt_name_is_a_type_error(tmp_path: Path) -> None:
    script = tmp_path / "user_script.py"
    script.write_text(
        "from cnc_objects.clients import names\n\n"
        "good: str = names.ch(1).mc_active_state_r\n"
        "bad: str = names.ch(1).mc_activ_state_r\n"
    )
    # tools/typecheck.py: mypy strict against the package as users import it
    # (a cache of its own: other tests run mypy at the same time in other workers)
    done = subprocess.run([sys.executable, str(ROOT / "tools" / "typecheck.py"), str(script),
                           "--no-incremental", "--follow-imports=silent",
                           "--cache-dir", str(tmp_path / "cache")],
                          capture_output=True, text=True, check=False)
    assert done.returncode == 1, done.stdout + done.stderr
    assert 'user_script.py:4: error: "_Ch" has no attribute "mc_activ_state_r"' in done.stdout
    assert "user_script.py:3" not in done.stdout
    assert "Found 1 error in 1 file" in done.stdout
