"""The object model and catalog: CNC objects, address rules, the address space."""

from .address_space import AddressSpace, Entry
from .catalog import ChannelLayout, MachineLayout, build_objects
from .model import Access, CncObject

__all__ = [
    "Access",
    "AddressSpace",
    "ChannelLayout",
    "CncObject",
    "Entry",
    "MachineLayout",
    "build_objects",
]
