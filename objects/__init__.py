"""The object model and catalog: CNC objects, address rules, the address space.

The names below load on first use (PEP 562): importing one light module of the package
(``objects.operator_data``, for ``cnc tool export``) does not build the catalog's modules,
which would cost every ``cnc`` start some 20 ms.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .address_space import AddressSpace, Entry
    from .catalog import ChannelLayout, MachineLayout, build_objects
    from .model import Access, CncObject

_HOMES = {  # exported name -> the module that defines it
    "Access": "model",
    "AddressSpace": "address_space",
    "ChannelLayout": "catalog",
    "CncObject": "model",
    "Entry": "address_space",
    "MachineLayout": "catalog",
    "build_objects": "catalog",
}

__all__ = [
    "Access",
    "AddressSpace",
    "ChannelLayout",
    "CncObject",
    "Entry",
    "MachineLayout",
    "build_objects",
]


def __getattr__(name: str) -> Any:
    """An exported name, imported from its module on first use."""
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{home}"), name)
    globals()[name] = value
    return value
