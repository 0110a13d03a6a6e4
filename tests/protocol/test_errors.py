"""ADS vocabulary: return codes and ProtocolError (protocol/errors.py), IntEnums of
protocol/constants.py. Numbers and names must be Beckhoff's, so that people who know
pyads and TwinCAT read them without a table.
"""

from __future__ import annotations

import pytest

from cnc_objects.protocol.constants import (
    AdsCommand,
    AdsState,
    CncPort,
    ReservedIndexGroup,
    TransmissionMode,
)
from cnc_objects.protocol.errors import AdsReturnCode, ProtocolError, describe_code

#: Beckhoff's ADS return codes (ADSERR_ names without the prefix).
BECKHOFF_CODES = {
    0x0: "NOERROR",
    0x6: "TARGETPORTNOTFOUND",
    0x7: "TARGETMACHINENOTFOUND",
    0x700: "DEVICE_ERROR",
    0x701: "DEVICE_SRVNOTSUPP",
    0x702: "DEVICE_INVALIDGRP",
    0x703: "DEVICE_INVALIDOFFSET",
    0x704: "DEVICE_INVALIDACCESS",
    0x705: "DEVICE_INVALIDSIZE",
    0x706: "DEVICE_INVALIDDATA",
    0x707: "DEVICE_NOTREADY",
    0x708: "DEVICE_BUSY",
    0x709: "DEVICE_INVALIDCONTEXT",
    0x70A: "DEVICE_NOMEMORY",
    0x70B: "DEVICE_INVALIDPARM",
    0x70C: "DEVICE_NOTFOUND",
    0x70D: "DEVICE_SYNTAX",
    0x70E: "DEVICE_INCOMPATIBLE",
    0x70F: "DEVICE_EXISTS",
    0x710: "DEVICE_SYMBOLNOTFOUND",
    0x711: "DEVICE_SYMBOLVERSIONINVALID",
    0x712: "DEVICE_INVALIDSTATE",
    0x713: "DEVICE_TRANSMODENOTSUPP",
    0x714: "DEVICE_NOTIFYHNDINVALID",
    0x715: "DEVICE_CLIENTUNKNOWN",
    0x716: "DEVICE_NOMOREHDLS",
    0x719: "DEVICE_TIMEOUT",
    0x745: "CLIENT_SYNCTIMEOUT",
    0x754: "CLIENT_SYNCRESINVALID",
}


# --------------------------------------------------------------------------- return codes


@pytest.mark.parametrize(
    ("code", "name"),
    sorted(BECKHOFF_CODES.items()),
    ids=lambda v: hex(v) if isinstance(v, int) else v,
)
def test_return_codes_have_beckhoffs_names(code: int, name: str) -> None:
    assert AdsReturnCode(code).name == name
    assert AdsReturnCode[name] == code


def test_return_code_values_are_unique() -> None:
    values = [member.value for member in AdsReturnCode]
    assert len(values) == len(set(values))


@pytest.mark.parametrize(
    ("code", "text"),
    [
        (0x704, "0x704 INVALIDACCESS"),
        (AdsReturnCode.DEVICE_INVALIDSIZE, "0x705 INVALIDSIZE"),
        (0x702, "0x702 INVALIDGRP"),
        (0x745, "0x745 SYNCTIMEOUT"),
        (0x754, "0x754 SYNCRESINVALID"),
        (0x6, "0x6 TARGETPORTNOTFOUND"),
        (0x0, "0x0 NOERROR"),
    ],
)
def test_describe_code(code: int, text: str) -> None:
    assert describe_code(code) == text


@pytest.mark.parametrize(("code", "text"), [(0x7FF, "0x7ff UNKNOWN"), (0x12345, "0x12345 UNKNOWN")])
def test_describe_unknown_code(code: int, text: str) -> None:
    assert describe_code(code) == text


def test_protocol_error_defaults() -> None:
    error = ProtocolError("bad frame")
    assert isinstance(error, ValueError)
    assert str(error) == "bad frame"
    assert error.invoke_id is None
    assert error.command is None
    assert error.code == AdsReturnCode.DEVICE_INVALIDPARM


def test_protocol_error_keeps_what_it_is_given() -> None:
    error = ProtocolError("x", invoke_id=9, command=2, code=AdsReturnCode.DEVICE_SRVNOTSUPP)
    assert (error.invoke_id, error.command, error.code) == (9, 2, 0x701)


# --------------------------------------------------------------------------- constants


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("READ_DEVICE_INFO", 1),
        ("READ", 2),
        ("WRITE", 3),
        ("READ_STATE", 4),
        ("WRITE_CONTROL", 5),
        ("ADD_DEVICE_NOTIFICATION", 6),
        ("DELETE_DEVICE_NOTIFICATION", 7),
        ("DEVICE_NOTIFICATION", 8),
        ("READ_WRITE", 9),
    ],
)
def test_ads_command_ids(name: str, value: int) -> None:
    assert AdsCommand[name] == value


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("SYM_HANDLE_BY_NAME", 0xF003),
        ("SYM_VALUE_BY_NAME", 0xF004),
        ("SYM_VALUE_BY_HANDLE", 0xF005),
        ("SYM_RELEASE_HANDLE", 0xF006),
        ("SUM_READ", 0xF080),
        ("SUM_WRITE", 0xF081),
        ("SUM_READ_WRITE", 0xF082),
    ],
)
def test_reserved_index_groups(name: str, value: int) -> None:
    assert ReservedIndexGroup[name] == value


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("NO_TRANS", 0),
        ("CLIENT_CYCLE", 1),
        ("CLIENT_ON_CHANGE", 2),
        ("SERVER_CYCLE", 3),
        ("SERVER_ON_CHANGE", 4),
        ("SERVER_CYCLE2", 5),
        ("SERVER_ON_CHANGE2", 6),
        ("CLIENT_1_REQ", 10),  # ADSTRANS_CLIENT1REQ = 10 in TwinCAT 3's TcAdsDef.h
    ],
)
def test_transmission_modes(name: str, value: int) -> None:
    assert TransmissionMode[name] == value


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("INVALID", 0), ("IDLE", 1), ("RESET", 2), ("INIT", 3), ("START", 4), ("RUN", 5),
        ("STOP", 6), ("SAVECFG", 7), ("LOADCFG", 8), ("POWERFAILURE", 9), ("POWERGOOD", 10),
        ("ERROR", 11), ("SHUTDOWN", 12), ("SUSPEND", 13), ("RESUME", 14), ("CONFIG", 15),
        ("RECONFIG", 16), ("STOPPING", 17), ("INCOMPATIBLE", 18), ("EXCEPTION", 19),
    ],
)
def test_ads_states(name: str, value: int) -> None:
    assert AdsState[name] == value


def test_cnc_ports() -> None:
    assert (CncPort.GEO, CncPort.SDA, CncPort.COM, CncPort.PLC) == (551, 552, 553, 851)


@pytest.mark.parametrize(
    "enum", [AdsCommand, AdsState, TransmissionMode, ReservedIndexGroup, CncPort]
)
def test_constant_values_are_unique(enum: type) -> None:
    values = [member.value for member in enum]
    assert len(values) == len(set(values))
