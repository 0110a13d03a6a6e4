"""The types the binding modules share: how an object is bound to the kernel for reads
and writes, and ``AreaBinding``, one catalog area's binders (``binding.AREAS``)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

from cnc_objects.objects import CncObject
from cnc_objects.objects.templates import CatalogSizes

from .kernel.kernel import Kernel, KernelCommand

Getter = Callable[[], Any]  # the value of one object, read from the snapshot
CommandFactory = Callable[[Any], KernelCommand]  # the command a written value becomes
Binder = Callable[[Kernel, CncObject], Getter]  # binds a readable object
WriteBinder = Callable[[Kernel, CncObject], CommandFactory]  # binds a writable object


class AreaBinding(NamedTuple):
    """The binders of one catalog area (``objects.catalog.AREAS``) by element name, for a
    machine's table sizes: ``readers(sizes)`` and ``writers(sizes)``."""

    readers: Callable[[CatalogSizes], dict[str, Binder]]
    writers: Callable[[CatalogSizes], dict[str, WriteBinder]]
