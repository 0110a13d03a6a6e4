"""The default machine's objects as the PLC symbol table lists them."""

from __future__ import annotations

#: The objects of the default machine: issue 27's 1004, + technology units and spindle,
#: manual mode, tools and offsets (issue 28: 350 + 108 + 278; G200/G201's manual offset
#: per axis: 6; the step clock's cnc_cycle_step_w: 1), alarms (issue 29: 6 + 13 fields x
#: (16 active + 32 history slots); wait reason and its text per channel: 2 x 2). A change
#: is deliberate: count it here. The cycle thread's scheduling (issue 30): 3. Issue 36's
#: operator objects: 2 channels x (14 COM + 4 HLI program_block_ignore), distance to go
#: per axis 6, settings 3; tool name/wear/life: 2 channels x 32 rows x 5. Issue 39: the
#: axis type per channel axis, 6.
DEFAULT_MACHINE_OBJECTS = (1004 + 350 + 108 + 278 + 6 + 1 + 6 + 13 * (16 + 32) + 2 * 2 + 3
                           + 2 * (14 + 4) + 6 + 3 + 2 * 32 * 5 + 6)
