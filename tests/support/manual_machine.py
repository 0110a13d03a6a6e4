"""A machine configuration for manual-mode tests, with its software limits."""

from __future__ import annotations

import copy

from cnc_objects.service.config import build_config
from cnc_objects.service.machine_config import DEFAULT_MACHINE

ACC_MM_S2 = 500.0  # small, so ramps take many cycles


JOG_MM_S, RAPID_MM_S, HOMING_MM_S = 20.0, 60.0, 15.0


LIMIT_MIN_MM, LIMIT_MAX_MM = -5.0, 8.0


REF_MM = 3.0


def machine(sw_limit_check: int = 1, **extra: object):
    """The default machine; X of channel 1 with small limits, monitored from start-up
    (P-AXIS-00705 ``swe_check`` 1: the tests need not home first; -1 is ISG's default,
    once referenced), and its manual parameters."""
    data = copy.deepcopy(DEFAULT_MACHINE)
    x = data["channels"][0]["axes"][0]
    x["limits"] = {"acc_max_mm_s2": ACC_MM_S2, "sw_limit_min_mm": LIMIT_MIN_MM,
                   "sw_limit_max_mm": LIMIT_MAX_MM, "sw_limit_check": sw_limit_check}
    x["manual"] = {"jog_vel_mm_s": JOG_MM_S, "jog_rapid_vel_mm_s": RAPID_MM_S,
                   "homing_vel_mm_s": HOMING_MM_S, "pos_refpkt_mm": REF_MM}
    data.update(extra)
    return build_config(data)
