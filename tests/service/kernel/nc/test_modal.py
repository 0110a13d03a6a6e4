"""The modal state: defaults, continuing across decoders (extended MDI), the API."""

from __future__ import annotations

import pytest

from cnc_objects.service.kernel.nc import (
    Compensation,
    DistanceMode,
    ModalState,
    MotionKind,
    NcError,
    NcErrorId,
    Plane,
)

from .support import decode, decoder


def test_fresh_modal_state() -> None:
    d = decoder("M30")
    assert d.modal.position_mm == (0.0, 0.0, 0.0)
    assert (d.modal.distance, d.modal.plane, d.modal.motion) == (
        DistanceMode.ABSOLUTE, Plane.XY, MotionKind.LINEAR)
    assert d.modal.feed_mm_min is None and d.modal.compensation == Compensation.OFF


def test_modal_state_after_a_program() -> None:
    d = decoder("G91 G18 G42 D2 G0 X5 F300 S800 T4\nM30")
    list(d.blocks())
    m = d.modal
    assert m.position_mm == (5.0, 0.0, 0.0)
    assert (m.distance, m.plane, m.motion, m.compensation) == (
        DistanceMode.INCREMENTAL, Plane.ZX, MotionKind.RAPID, Compensation.RIGHT)
    assert (m.feed_mm_min, m.tool_offset, m.spindle_speed_rpm, m.tool) == (300.0, 2, 800.0, 4)


def test_manual_blocks_continue_the_modal_state() -> None:
    modal = ModalState(position_mm=(1.0, 2.0, 3.0))
    first = decoder("G91 G1 X1 F600", modal=modal, manual=True)
    assert [b.motion.end_mm for b in first.blocks()] == [(2.0, 2.0, 3.0)]
    second = decoder("X1\nY-2", modal=first.modal, manual=True)
    blocks = list(second.blocks())
    assert [b.motion.end_mm for b in blocks] == [(3.0, 2.0, 3.0), (3.0, 0.0, 3.0)]
    assert all(b.manual and b.motion.feed_mm_s == 10.0 for b in blocks)
    assert second.modal is modal


def test_caller_sets_the_start_position() -> None:
    modal = ModalState(position_mm=(10.0, 0.0, 0.0))
    assert decode("G1 X20 F60\nM30", modal=modal)[0].motion.start_mm == (10.0, 0.0, 0.0)


def test_blocks_runs_once() -> None:
    d = decoder("M30")
    list(d.blocks())
    with pytest.raises(RuntimeError):
        d.blocks()


@pytest.mark.parametrize("axes", [("X", "X"), ("L",), ("XY",), ("I",), ("x",)])
def test_invalid_axis_names(axes) -> None:
    with pytest.raises(ValueError):
        decoder("M30", axes=axes)


def test_modal_position_must_match_the_axes() -> None:
    with pytest.raises(ValueError):
        decoder("M30", modal=ModalState(position_mm=(0.0, 0.0)))


def test_other_axis_sets() -> None:
    blocks = decode("G0 X1 Y2 Z3 A45 B-5 C90\nM30", axes=("X", "Y", "Z", "A", "B", "C"))
    assert blocks[0].motion.end_mm == (1.0, 2.0, 3.0, 45.0, -5.0, 90.0)
    assert decode("G0 Z1\nM30", axes=("Z",))[0].motion.end_mm == (1.0,)


def test_nc_error_format_and_fields() -> None:
    e = NcError(NcErrorId.LABEL_NOT_FOUND, "a.nc", 3, 7, "label N5 not found")
    assert str(e) == "error 20227: a.nc:3:7: label N5 not found"
    assert (e.id, e.file, e.line, e.column, e.message) == (
        20227, "a.nc", 3, 7, "label N5 not found")
    import pickle

    copy = pickle.loads(pickle.dumps(e))
    assert str(copy) == str(e) and copy.id == e.id


def test_error_ids() -> None:
    values = [int(m) for m in NcErrorId]
    assert len(values) == len(set(values))
    # the decoder's ids, ISG's kinematic transformation ids (292xxx) and ISG's id of a
    # write of the zero offset in effect (14421)
    assert all(20000 <= v <= 22999 or 292000 <= v <= 292999 or v == 14421 for v in values)
    assert 21309 not in values  # reserved for later use
    assert NcErrorId(22073) == NcErrorId.CONTOUR_CLEAR_IN_RT_LOOP  # ISG's id


def test_a_block_with_an_error_leaves_the_modal_state_unchanged() -> None:
    modal = ModalState()
    list(decoder("G1 X1 F100", modal=modal, manual=True).blocks())
    with pytest.raises(NcError):
        list(decoder("G91 G2 X5 I99 F50", modal=modal, manual=True).blocks())
    assert (modal.position_mm, modal.distance, modal.motion, modal.feed_mm_min) == (
        (1.0, 0.0, 0.0), DistanceMode.ABSOLUTE, MotionKind.LINEAR, 100.0)
    assert decode("X2", modal=modal, manual=True)[0].motion.start_mm == (1.0, 0.0, 0.0)
