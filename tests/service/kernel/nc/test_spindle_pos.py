"""``M19 S.POS=<degrees>``: the decoder carries the angle on the block (0..360)."""

from __future__ import annotations

import pytest

from cnc_objects.service.kernel.nc.errors import NcErrorId

from .support import decode, error_of


@pytest.mark.parametrize(("text", "angle"), [
    ("S100 M19 S.POS=90", 90.0), ("S.POS = 45 + 3 S100 M19", 48.0),
    ("S100 M19 S.POS=450", 90.0), ("S100 M19 S.POS=-45", 315.0), ("S100 M19", None)])
def test_s_pos_is_the_angle_of_the_m19(text: str, angle: float | None) -> None:
    first = decode(f"{text}\nM30\n")[0]
    assert first.m_functions == (19,) and first.spindle_pos_deg == angle


@pytest.mark.parametrize(("text", "error"), [
    ("S100 M19 S.POS=1 S.POS=2", NcErrorId.SPINDLE_POS_TWICE),
    ("S100 M19 S.POS 90", NcErrorId.EXPRESSION_SYNTAX)])
def test_s_pos_errors(text: str, error: NcErrorId) -> None:
    assert error_of(f"{text}\nM30\n").id == error
