"""SysHscSettings: switch the machine's high-speed behaviour (§5).

@P1 = 1 deselect, 2 rough, 3 prefinish, 4 finish (default 1) calls the program named
in the channel parameter ``hscs.<mode>.prog`` (a file of the program store, run like
``L <name>``, so it ends with M17). The tolerances ``hscs.<mode>.tolerance`` are read
in NC programs as ``V.G.HSCS.<MODE>.TOLERANCE`` in the program's unit (this decoder
programs in mm: it has no G70/G71, so the value is mm), typically in ``#HSC ON
[.. PATH_DEV=V.G.HSCS.FINISH.TOLERANCE]`` inside that program.
"""

from __future__ import annotations

from ..errors import NcErrorId
from ..technology import HSCS_MODES
from .spec import BuiltinCycle, CycleContext, ParamSpec


def _run(context: CycleContext) -> str | None:
    mode = HSCS_MODES[int(context.params[1]) - 1]
    setting = context.decoder.surroundings.hscs.get(mode)
    prog = setting.prog if setting is not None else ""
    if not prog:
        raise context.error(
            NcErrorId.CYCLE_NOT_FOUND,
            f"SysHscSettings.ecy @P1={int(context.params[1])} ({mode}): the channel parameter "
            f"hscs.{mode.lower()}.prog names no program", 1)
    if not context.decoder.has_file(prog):
        raise context.error(
            NcErrorId.CYCLE_NOT_FOUND,
            f"SysHscSettings.ecy ({mode}): hscs.{mode.lower()}.prog names {prog}, which is "
            "not in the program store", 1)
    return f"L {prog}\nM17\n"


HSC_SETTINGS = BuiltinCycle(
    "SysHscSettings.ecy",
    {1: ParamSpec("mode 1 deselect, 2 rough, 3 prefinish, 4 finish", 1, 1, 4, True)},
    _run,
)
