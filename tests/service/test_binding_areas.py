"""One way to add objects: a catalog area (``objects.catalog.AREAS``) and its binders
(``service.binding.AREAS``), each listed once, in the same order; every object of every
area is bound, and no element is bound by two areas."""

from __future__ import annotations

import pytest

from cnc_objects.objects import catalog
from cnc_objects.objects.templates import CatalogSizes
from cnc_objects.service import binding
from cnc_objects.service.binding_types import AreaBinding

SIZES = CatalogSizes(tool_entries=3, zero_offset_groups=4, alarm_history=5)


def test_each_catalog_area_has_its_binders_in_the_same_place() -> None:
    assert len(binding.AREAS) == len(catalog.AREAS)
    for area, binders in zip(catalog.AREAS, binding.AREAS, strict=True):
        elements = {t.element for t in area(SIZES)}
        bound = binders.readers(SIZES).keys() | binders.writers(SIZES).keys()
        if binders is binding.AREAS[0]:  # the core: the service's own figures too
            bound |= binding.SERVICE_READERS.keys()
        assert elements - bound == set(), area.__name__  # every element of the area
        assert bound - elements == set(), area.__name__  # and nothing of another


def test_every_readable_and_writable_element_is_bound() -> None:
    readers, writers = binding.area_readers(SIZES), binding.area_writers(SIZES)
    service = binding.SERVICE_READERS.keys()
    for template in catalog.templates(SIZES):
        if template.access.readable:
            assert template.element in readers or template.element in service or (
                template.element in writers), template.element  # a command echoes
        if template.access.writable:
            assert template.element in writers, template.element


def test_an_element_bound_by_two_areas_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    twice = AreaBinding(lambda sizes: binding.READERS, lambda sizes: {})
    monkeypatch.setattr(binding, "AREAS", (*binding.AREAS, twice))
    with pytest.raises(ValueError, match="readers bound twice: .*mc_active_state_r"):
        binding.area_readers(SIZES)
