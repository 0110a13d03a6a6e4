"""ADS return codes and the protocol's own exception.

Codes cross the wire as numbers; only the client API turns a code into an exception, and
its message names the code the way Beckhoff's return-code table does.
"""

from __future__ import annotations

from enum import IntEnum


class AdsReturnCode(IntEnum):
    """ADS return codes (Beckhoff ADS return code table), by their ADSERR_ names."""

    NOERROR = 0x0  # no error
    INTERNAL = 0x1  # internal error
    NORTIME = 0x2  # no real-time
    ALLOCLOCKEDMEM = 0x3  # allocation of locked memory failed
    INSERTMAILBOX = 0x4  # mailbox full, message could not be sent
    WRONGRECEIVEHMSG = 0x5  # wrong HMSG
    TARGETPORTNOTFOUND = 0x6  # target port not found: ADS server not started or reachable
    TARGETMACHINENOTFOUND = 0x7  # target machine not found
    UNKNOWNCMDID = 0x8  # unknown command id
    BADTASKID = 0x9  # invalid task id
    NOIO = 0xA  # no IO
    UNKNOWNAMSCMD = 0xB  # unknown AMS command
    WIN32ERROR = 0xC  # Win32 error
    PORTNOTCONNECTED = 0xD  # port not connected
    INVALIDAMSLENGTH = 0xE  # invalid AMS length
    INVALIDAMSNETID = 0xF  # invalid AMS net id
    ROUTER_MAILBOXFULL = 0x502  # the port's mailbox is full: the request was rejected
    DEVICE_ERROR = 0x700  # general device error
    DEVICE_SRVNOTSUPP = 0x701  # service not supported by the server
    DEVICE_INVALIDGRP = 0x702  # invalid index group
    DEVICE_INVALIDOFFSET = 0x703  # invalid index offset
    DEVICE_INVALIDACCESS = 0x704  # reading or writing not permitted
    DEVICE_INVALIDSIZE = 0x705  # parameter size not correct
    DEVICE_INVALIDDATA = 0x706  # invalid parameter value(s)
    DEVICE_NOTREADY = 0x707  # device is not in a ready state
    DEVICE_BUSY = 0x708  # device is busy
    DEVICE_INVALIDCONTEXT = 0x709  # invalid operating system context
    DEVICE_NOMEMORY = 0x70A  # insufficient memory
    DEVICE_INVALIDPARM = 0x70B  # invalid parameter value(s)
    DEVICE_NOTFOUND = 0x70C  # not found (files, ...)
    DEVICE_SYNTAX = 0x70D  # syntax error in file or command
    DEVICE_INCOMPATIBLE = 0x70E  # objects do not match
    DEVICE_EXISTS = 0x70F  # object already exists
    DEVICE_SYMBOLNOTFOUND = 0x710  # symbol not found
    DEVICE_SYMBOLVERSIONINVALID = 0x711  # invalid symbol version
    DEVICE_INVALIDSTATE = 0x712  # device (server) is in an invalid state
    DEVICE_TRANSMODENOTSUPP = 0x713  # AdsTransMode not supported
    DEVICE_NOTIFYHNDINVALID = 0x714  # notification handle is invalid
    DEVICE_CLIENTUNKNOWN = 0x715  # notification client not registered
    DEVICE_NOMOREHDLS = 0x716  # no further handle available
    DEVICE_INVALIDWATCHSIZE = 0x717  # notification size too large
    DEVICE_NOTINIT = 0x718  # device not initialised
    DEVICE_TIMEOUT = 0x719  # device has a timeout
    DEVICE_NOINTERFACE = 0x71A  # interface query failed
    DEVICE_INVALIDINTERFACE = 0x71B  # wrong interface requested
    DEVICE_INVALIDCLSID = 0x71C  # class id is invalid
    DEVICE_INVALIDOBJID = 0x71D  # object id is invalid
    DEVICE_PENDING = 0x71E  # request pending
    DEVICE_ABORTED = 0x71F  # request aborted
    DEVICE_WARNING = 0x720  # signal warning
    DEVICE_INVALIDARRAYIDX = 0x721  # invalid array index
    DEVICE_SYMBOLNOTACTIVE = 0x722  # symbol not active
    DEVICE_ACCESSDENIED = 0x723  # access denied
    CLIENT_ERROR = 0x740  # client error
    CLIENT_INVALIDPARM = 0x741  # service contains an invalid parameter
    CLIENT_LISTEMPTY = 0x742  # polling list is empty
    CLIENT_VARUSED = 0x743  # variable connection already in use
    CLIENT_DUPLINVOKEID = 0x744  # invoke id in use
    CLIENT_SYNCTIMEOUT = 0x745  # timeout elapsed: remote terminal not responding
    CLIENT_W32ERROR = 0x746  # error in Win32 subsystem
    CLIENT_TIMEOUTINVALID = 0x747  # invalid client timeout value
    CLIENT_PORTNOTOPEN = 0x748  # port not open
    CLIENT_NOAMSADDR = 0x749  # no AMS address
    CLIENT_SYNCINTERNAL = 0x750  # internal error in ADS sync
    CLIENT_ADDHASH = 0x751  # hash table overflow
    CLIENT_REMOVEHASH = 0x752  # key not found in hash table
    CLIENT_NOMORESYM = 0x753  # no symbols in the cache
    CLIENT_SYNCRESINVALID = 0x754  # invalid response received
    CLIENT_SYNCPORTLOCKED = 0x755  # sync port is locked


def describe_code(code: int) -> str:
    """Return ``0x704 INVALIDACCESS`` for a known code, ``0x7ff UNKNOWN`` otherwise."""
    try:
        name = AdsReturnCode(code).name
    except ValueError:
        return f"0x{code:x} UNKNOWN"
    short = name.split("_", 1)[1] if name.startswith(("DEVICE_", "CLIENT_")) else name
    return f"0x{code:x} {short}"


class ProtocolError(ValueError):
    """A frame that does not decode or has the wrong shape.

    ``invoke_id`` and ``command`` are set when they could be read, so that the server can
    still answer the sender with an error reply; ``code`` is the ADS code to answer with.
    """

    def __init__(
        self,
        message: str,
        *,
        invoke_id: int | None = None,
        command: int | None = None,
        code: AdsReturnCode = AdsReturnCode.DEVICE_INVALIDPARM,
    ) -> None:
        super().__init__(message)
        self.invoke_id = invoke_id
        self.command = command
        self.code = code
