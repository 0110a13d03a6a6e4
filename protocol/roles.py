"""Roles of the service's clients and what each may ask: the one access policy of both
front ends (ZeroMQ: a CURVE key's role; ADS: a route's role), sans I/O.

Every request needs a role; a peer whose role is lower gets ADS 0x704 INVALIDACCESS and
keeps its connection:

============================  ==========  ====================================================
request                       needs       why
============================  ==========  ====================================================
ReadDeviceInfo, ReadState     monitor     reads
Read (objects, program and    monitor     reads
output lists)
ReadWrite (by name, handles,  monitor     reads: these groups answer data, change nothing
symbols, program and output
download, sum read)
Add/DeleteDeviceNotification  monitor     subscribing changes nothing in the machine
Browse                        monitor     reads the catalog
Write 0xF006 (release handle) monitor     handles are stable per object: nothing changes
Write (any other address)     operator    changes the machine: objects, programs run;
                                          deleting output files (the kernel's own)
WriteControl                  operator    RUN, STOP, RESET of the kernel
ReadWrite 0xF081 (sum write)  per item    each slot as a Write at its address
Write program store (upload,  admin       the programs every operator runs
delete)
============================  ==========  ====================================================
"""

from __future__ import annotations

from enum import IntEnum

from .constants import PROGRAM_STORE_GROUP, AdsCommand, CncPort
from .constants import ReservedIndexGroup as RIG


class Role(IntEnum):
    """What a client may do; each role may everything the lower ones may."""

    MONITOR = 1  # read, browse, subscribe; list and download programs
    OPERATOR = 2  # also write objects and command the kernel: run programs, MDI, reset
    ADMIN = 3  # also the program store: upload and delete programs

    @property
    def label(self) -> str:
        """The role as written in configurations, key directories and messages."""
        return self.name.lower()

    @classmethod
    def parse(cls, text: str) -> Role:
        """The role named ``text`` (any case); ``ValueError`` lists the roles."""
        try:
            return cls[text.strip().upper()]
        except KeyError:
            raise ValueError(f"unknown role {text!r}; the roles are {ROLE_NAMES}") from None

    def may(self, needed: Role) -> bool:
        """True when this role covers ``needed``."""
        return self >= needed


ROLE_NAMES = ", ".join(r.label for r in Role)
LOOPBACK_ROLE = Role.ADMIN  # peers on loopback when the service runs without keys

#: The role each command needs, but for Write (by address: ``role_to_write``) and a sum
#: write (per item). Commands not listed never reach the dispatcher (they do not decode).
COMMAND_ROLES: dict[int, Role] = {
    AdsCommand.READ_DEVICE_INFO: Role.MONITOR,
    AdsCommand.READ: Role.MONITOR,
    AdsCommand.READ_STATE: Role.MONITOR,
    AdsCommand.ADD_DEVICE_NOTIFICATION: Role.MONITOR,
    AdsCommand.DELETE_DEVICE_NOTIFICATION: Role.MONITOR,
    AdsCommand.READ_WRITE: Role.MONITOR,
    AdsCommand.BROWSE: Role.MONITOR,
    AdsCommand.WRITE_CONTROL: Role.OPERATOR,
}


def role_to_write(port: int, group: int) -> Role:
    """The role an ADS Write at ``port``/``group`` needs."""
    if group == PROGRAM_STORE_GROUP and port == CncPort.COM:
        return Role.ADMIN
    if group == RIG.SYM_RELEASE_HANDLE:
        return Role.MONITOR
    return Role.OPERATOR


def roles_that_may(needed: Role) -> str:
    """``"operator or admin"``: the roles that cover ``needed``, for messages."""
    names = [r.label for r in Role if r.may(needed)]
    return names[0] if len(names) == 1 else f"{', '.join(names[:-1])} or {names[-1]}"
