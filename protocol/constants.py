"""ADS vocabulary: command ids, states, transmission modes, ports and reserved index groups.

Numbers and names follow Beckhoff's ADS specification, so that anyone who knows pyads or
TwinCAT reads them without a table. One comment per member says what it is.
"""

from __future__ import annotations

from enum import IntEnum, IntFlag


class AdsCommand(IntEnum):
    """ADS command ids, as carried in the AMS header and in our frames."""

    INVALID = 0  # never sent; a frame with it is refused
    READ_DEVICE_INFO = 1  # name and version of the device
    READ = 2  # read data at index group/offset
    WRITE = 3  # write data at index group/offset
    READ_STATE = 4  # ADS state and device state
    WRITE_CONTROL = 5  # change ADS state and device state
    ADD_DEVICE_NOTIFICATION = 6  # subscribe to a value
    DELETE_DEVICE_NOTIFICATION = 7  # end a subscription
    DEVICE_NOTIFICATION = 8  # server to client: subscribed samples
    READ_WRITE = 9  # write data, then read data, in one request
    BROWSE = 0x100  # project extension: object descriptions matching a glob pattern


class AdsState(IntEnum):
    """ADS states (ADSSTATE_*), as reported by ReadState and set by WriteControl."""

    INVALID = 0  # not a state
    IDLE = 1  # idle
    RESET = 2  # reset requested / resetting
    INIT = 3  # initialising
    START = 4  # starting
    RUN = 5  # running
    STOP = 6  # stopped
    SAVECFG = 7  # saving configuration
    LOADCFG = 8  # loading configuration
    POWERFAILURE = 9  # power failure
    POWERGOOD = 10  # power good
    ERROR = 11  # error
    SHUTDOWN = 12  # shutting down
    SUSPEND = 13  # suspended
    RESUME = 14  # resuming
    CONFIG = 15  # configuration mode
    RECONFIG = 16  # reconfiguring
    STOPPING = 17  # stopping
    INCOMPATIBLE = 18  # incompatible
    EXCEPTION = 19  # exception


class TransmissionMode(IntEnum):
    """ADS notification transmission modes (ADSTRANS_*)."""

    NO_TRANS = 0  # no transmission
    CLIENT_CYCLE = 1  # client polls cyclically (not a server mode)
    CLIENT_ON_CHANGE = 2  # client polls on change (not a server mode)
    SERVER_CYCLE = 3  # server sends every cycle time
    SERVER_ON_CHANGE = 4  # server sends when the value changed, checked every cycle time
    SERVER_CYCLE2 = 5  # like SERVER_CYCLE (TwinCAT 3 spelling)
    SERVER_ON_CHANGE2 = 6  # like SERVER_ON_CHANGE (TwinCAT 3 spelling)
    CLIENT_1_REQ = 10  # one request only (ADSTRANS_CLIENT1REQ)


class ReservedIndexGroup(IntEnum):
    """Index groups whose meaning ADS fixes for every port."""

    SYM_HANDLE_BY_NAME = 0xF003  # ReadWrite: name in, UNS32 handle out
    SYM_VALUE_BY_NAME = 0xF004  # ReadWrite: name in, value out
    SYM_VALUE_BY_HANDLE = 0xF005  # Read/Write with offset = handle
    SYM_RELEASE_HANDLE = 0xF006  # Write the UNS32 handle to release it
    SYM_VERSION = 0xF008  # Read: the symbol table's version (one byte)
    SYM_INFO_BY_NAME_EX = 0xF009  # ReadWrite: name in, AdsSymbolEntry out
    SYM_UPLOAD = 0xF00B  # Read: every AdsSymbolEntry, one after the other
    SYM_UPLOAD_INFO = 0xF00C  # Read: symbol count and upload length (8 bytes)
    SYM_DT_UPLOAD = 0xF00E  # Read: every AdsDatatypeEntry, one after the other
    SYM_UPLOAD_INFO2 = 0xF00F  # Read: AdsSymbolUploadInfo2 (24 bytes; 64 with TwinCAT 3 fields)
    SYM_DT_INFO_BY_NAME_EX = 0xF011  # ReadWrite: type name in, AdsDatatypeEntry out
    SUM_READ = 0xF080  # ReadWrite: N x (group, offset, length) in, N codes + data out
    SUM_WRITE = 0xF081  # ReadWrite: N x (group, offset, length) + data in, N codes out
    SUM_READ_WRITE = 0xF082  # ReadWrite: N x (group, offset, rlen, wlen) + data in
    DEVICE_DATA = 0xF100  # Read: offset 0 ADS state (UINT), offset 2 device state (UINT)


#: Offsets in ``ReservedIndexGroup.DEVICE_DATA`` (ADSIOFFS_DEVDATA_*).
DEVICE_DATA_ADS_STATE = 0x0  # UINT: the ADS state of the port's device
DEVICE_DATA_DEVICE_STATE = 0x2  # UINT: its device state


class CncPort(IntEnum):
    """ADS ports of the CNC tasks and of the PLC whose variables we serve."""

    GEO = 551  # interpolator, position controller: path and axis real-time data
    SDA = 552  # decoder: NC variables
    COM = 553  # HMI-facing mc_*, cnc_*, ac_* objects
    PLC = 851  # TwinCAT PLC runtime 1: the HLI elements, served as symbols


class AmsPort(IntEnum):
    """AMS ports beside the CNC tasks that an ADS router answers on."""

    SYSTEM_SERVICE = 10000  # the TwinCAT system service: ReadState, ReadDeviceInfo


class SystemServiceGroup(IntEnum):
    """The TwinCAT system service's file functions (index groups at ``AmsPort.SYSTEM_SERVICE``,
    each an ADS ReadWrite; the index offset is the file handle, or the open flags): what
    Tc2_System's FB_FileOpen / FB_FileRead / FB_FileWrite / FB_FileClose / FB_FileDelete and
    AdsLib's ``AdsFile`` send. Served on the program store (``service/ads/file_service``)."""

    FOPEN = 120  # offset: mode | path << 16; write: the file name; read: the handle (u32)
    FCLOSE = 121  # offset: the handle
    FREAD = 122  # offset: the handle; read: up to read length bytes (fewer at the end)
    FWRITE = 123  # offset: the handle; write: the bytes
    FDELETE = 131  # offset: path << 16; write: the file name


class FileOpenMode(IntFlag):
    """``nMode`` of FB_FileOpen (FOPEN_MODE*), the low 16 bits of an FOPEN's index offset."""

    READ = 0x1  # "r"
    WRITE = 0x2  # "w": an empty file, replacing an older one
    APPEND = 0x4  # "a"
    PLUS = 0x8  # "+": read and write
    BINARY = 0x10  # "b"
    TEXT = 0x20  # "t": CR LF translation on Windows


#: ``ePath`` of FB_FileOpen (E_OpenPath): the high 16 bits of an FOPEN's index offset.
#: PATH_GENERIC (1) is the only path served: the program store.
FILE_PATH_GENERIC = 1
FILE_PATH_SHIFT = 16


class AmsStateFlag(IntEnum):
    """Bits of the AMS header's state flags."""

    RESPONSE = 0x0001  # set in replies, clear in requests
    ADS_COMMAND = 0x0004  # an ADS command (every frame this server handles)
    UDP = 0x0040  # the frame came over UDP (never here: AMS/TCP only)


#: TCP port of AMS/TCP (ADS routers listen here; AdsLib always dials it).
AMS_TCP_PORT = 48898


class AmsTcpCommand(IntEnum):
    """The first u16 of the AMS/TCP header ("reserved" in the ADS specification): 0 for an
    AMS command; otherwise a command to the local AMS router, as TwinCAT's router and
    ads-client (``AMS_HEADER_FLAG``) number them. Answered in ``protocol.ams_router``."""

    AMS_COMMAND = 0x0000  # an AMS header and ADS data follow
    PORT_CLOSE = 0x0001  # data: the client's AMS port (u16) to release
    PORT_CONNECT = 0x1000  # data: the AMS port wanted (u16, 0: any); reply: Net ID, port
    ROUTER_NOTE = 0x1001  # router to client: the router's state (u32); never a request
    GET_LOCAL_NET_ID = 0x1002  # data: ignored (4 bytes); reply: the router's AMS Net ID

#: Largest AMS/TCP frame a connection may send by default (bytes after the 6-byte
#: AMS/TCP header); a longer one closes that connection.
AMS_MAX_FRAME_BYTES = 1 << 20


#: The most sub-requests one sum command may carry (TwinCAT allows 500).
SUM_COMMAND_MAX_ITEMS = 500

#: Largest data block a single request may carry (bytes). Larger requests get 0x705.
MAX_DATA_BYTES = 1 << 20


#: Index group of the program store on the COM port (project-defined: ISG documents no
#: ADS file service for NC programs). Offsets are ``ProgramStoreOffset``.
PROGRAM_STORE_GROUP = 0x150000

#: The longest tool life a tool list row takes (s, ``wz[i].life_max``): about 32 years
#: of cutting (the kernel refuses more, the operator data file too).
TOOL_LIFE_MAX_S = 1e9
#: Bytes of a tool's name ``wz[i].name`` (STRING, NUL-terminated: one less character).
TOOL_NAME_CHARS = 32

#: Largest file one frame carries whole (bytes): a one-frame upload or download of a
#: program, one file of the output area; a larger program is uploaded in chunks.
PROGRAM_MAX_BYTES = 1_000_000

#: Largest program the store takes by default (``[limits] program_max_bytes``): a CAM
#: finishing program of 200 MB fits; beyond one frame a program goes in chunks.
PROGRAM_STORE_MAX_BYTES = 256 << 20

#: Bytes the program store holds in all its programs together (``[limits]
#: store_max_total_bytes``); a chunked upload that would exceed it is abandoned (0x70A).
STORE_MAX_TOTAL_BYTES = 4 << 30

#: Longest program name (characters): ISG file names are STRING(84) with the NUL.
PROGRAM_NAME_MAX_CHARS = 83


class ProgramStoreOffset(IntEnum):
    """Operations of the program store (index offsets in ``PROGRAM_STORE_GROUP``)."""

    LIST = 1  # Read: one line per program, "name<TAB>size_bytes<TAB>mtime_unix_s\n" (UTF-8)
    UPLOAD = 2  # Write: name (CP1252), NUL, content; replaces atomically
    DOWNLOAD = 3  # ReadWrite: name in, content out (read length >= size)
    DELETE = 4  # Write: name
    # A program larger than one frame goes in chunks, one upload per connection at a time
    # (``service/program_uploads``): the store keeps it in a temporary file until the commit.
    UPLOAD_OPEN = 5  # Write: name (CP1252), NUL[, size u64 LE]; abandons an earlier upload
    UPLOAD_CHUNK = 6  # Write: position (u64 LE, = bytes sent so far), then the bytes
    UPLOAD_COMMIT = 7  # Write: total size (u64 LE); the program replaces the old atomically
    UPLOAD_ABANDON = 8  # Write: nothing; the temporary file is removed
    # A view of a huge program reads a window of its lines (``protocol/program_lines``).
    READ_LINES = 9  # ReadWrite: first line, count, name in; total lines, the lines out


#: Bytes of one chunk of a chunked upload the client sends (``UPLOAD_CHUNK``).
UPLOAD_CHUNK_BYTES = 256 * 1024


#: Index group of the output area on the COM port (project-defined): the files the kernel
#: writes (#MSG SAVE, cycle results, error logs, syntax check logs, PROD_TIME traces),
#: apart from the program store. Offsets are ``OutputAreaOffset``.
OUTPUT_AREA_GROUP = 0x150001


class OutputAreaOffset(IntEnum):
    """Operations of the output area (index offsets in ``OUTPUT_AREA_GROUP``)."""

    LIST = 1  # Read: one line per file, "name<TAB>size_bytes<TAB>mtime_unix_s\n" (UTF-8)
    DOWNLOAD = 3  # ReadWrite: name in, content out (read length >= size)
    DELETE = 4  # Write: name (operator and admin)

#: The ZAP status the service's handshake refuses a ZeroMQ connection with when its
#: connection table is full ([limits] connections_per_front_end). ZeroMQ carries only
#: the status code to the client (its monitor's EVENT_HANDSHAKE_FAILED_AUTH value); the
#: service answers a key not in the allow-list with 400, so 500 means "no room".
ZAP_STATUS_TABLE_FULL = 500
