"""The machine functions of the client in engineering units, as one mixin of
``AsyncClient``: jog and home (``manual_ops``), tools and zero offsets
(``tooling_ops``), the spindle (``spindle_ops``). The ``cnc`` commands ``jog``, ``home``,
``tool``, ``offsets`` and ``spindle`` call these methods, so each fact lives here once."""

from __future__ import annotations

from .spindle_ops import SpindleOps
from .tooling_ops import ToolingOps


class MachineOps(ToolingOps, SpindleOps):
    """Jog, home, tools, zero offsets and the spindle, in mm, rpm and %."""
