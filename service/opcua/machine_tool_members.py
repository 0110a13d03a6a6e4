"""The members of the MachineTool (OPC 40501-1) instance and the objects they show, as
tables: identification, the machine's and each channel's and spindle's monitoring, the
active program, the tool list. Each entry is a ``Source`` (``sources``); a member the
twin cannot fill is ``fixed`` with the reason (docs/opcua.md, "MachineTool").

The twin's states as the MachineTool nodeset's enumerations (values as published):

- ``MachineOperationMode`` (40501-1 10.4) of channel 1's mode: AUTOMATIC -> Automatic 1;
  MANUAL and MDI -> Manual 0 (an operator drives the machine); STANDBY and REFERENCE ->
  Other 5.
- ``ChannelMode`` (10.2): AUTOMATIC -> Automatic 0, MDI -> MdaMdi 1, MANUAL ->
  JogManual 2, REFERENCE -> Reference 6, STANDBY -> Other 7.
- ``ChannelState`` (10.1): ACTIVE -> Active 0, HOLD and ERROR -> Interrupted 1, every
  other state -> Reset 2.
- ``ProductionProgramStateMachineType`` (9.4.2): ACTIVE -> Running 1, HOLD ->
  Interrupted 3, ERROR -> Aborted 4; READY or SELECTED after a program ran (the channel
  names an active program) -> Ended 2, else Initializing 0.
"""

from __future__ import annotations

from collections.abc import Callable
from datetime import UTC, datetime
from typing import Any

from asyncua import ua

from cnc_objects.protocol.values import ChannelMode, ChannelState

from .cnc_members import OVERRIDE_RANGE
from .sources import Source, derived, fixed, plain, scaled

_U32, _U16, _I32 = ua.VariantType.UInt32, ua.VariantType.UInt16, ua.VariantType.Int32
_B, _S, _D = ua.VariantType.Boolean, ua.VariantType.String, ua.VariantType.Double

#: MachineOperationMode: Manual 0, Automatic 1, Setup 2, AutoWithManualIntervention 3,
#: Service 4, Other 5
MACHINE_OPERATION_MODE: dict[int, int] = {
    ChannelMode.AUTOMATIC: 1, ChannelMode.MANUAL: 0, ChannelMode.MDI: 0,
    ChannelMode.STANDBY: 5, ChannelMode.REFERENCE: 5}
#: ChannelMode: Automatic 0, MdaMdi 1, JogManual 2, JogIncrement 3, TeachingHandle 4,
#: Remote 5, Reference 6, Other 7
CHANNEL_MODE: dict[int, int] = {
    ChannelMode.AUTOMATIC: 0, ChannelMode.MDI: 1, ChannelMode.MANUAL: 2,
    ChannelMode.REFERENCE: 6, ChannelMode.STANDBY: 7}
#: ChannelState: Active 0, Interrupted 1, Reset 2
CHANNEL_STATE: dict[int, int] = {
    ChannelState.ACTIVE: 0, ChannelState.HOLD: 1, ChannelState.ERROR: 1}
_OTHER_MODE, _OTHER_CHANNEL_MODE, _RESET = 5, 7, 2

#: ProductionProgramStateMachineType's states: (name, number), as the nodeset numbers them
PROGRAM_STATES: tuple[str, ...] = ("Initializing", "Running", "Ended", "Interrupted", "Aborted")
_PROGRAM_STATE: dict[int, int] = {ChannelState.ACTIVE: 1, ChannelState.HOLD: 3,
                                  ChannelState.ERROR: 4}
SECONDS_PER_HOUR = 3600


def machine_operation_mode(mode: int) -> int:
    """MachineOperationMode of the twin's channel mode."""
    return MACHINE_OPERATION_MODE.get(mode, _OTHER_MODE)


def channel_mode(mode: int) -> int:
    """ChannelMode of the twin's channel mode."""
    return CHANNEL_MODE.get(mode, _OTHER_CHANNEL_MODE)


def channel_state(state: int) -> int:
    """ChannelState of the twin's channel state."""
    return CHANNEL_STATE.get(state, _RESET)


def program_state(state: int, program: str) -> int:
    """The number of the ProductionProgramStateMachine's state (``PROGRAM_STATES``)."""
    if state in _PROGRAM_STATE:
        return _PROGRAM_STATE[state]
    return 2 if program else 0


def identification(vendor: str, machine: str, product_uri: str) -> dict[str, Source]:
    """MachineToolIdentificationType's members (40501-1 8.2; Machinery 10.1): the service
    is the machine; its identity does not change while it runs. Model, ProductCode,
    SoftwareRevision and YearOfConstruction are optional in the model; the umati
    dashboard shows them."""
    return {
        "Manufacturer": fixed(ua.LocalizedText(vendor), ua.VariantType.LocalizedText,
                              "the service's vendor name"),
        "Model": fixed(ua.LocalizedText(f"{vendor} CNC twin"), ua.VariantType.LocalizedText,
                       "the service's product"),
        "SerialNumber": fixed(machine, _S, "the twin has no serial number: the machine "
                              "configuration's name ([machine] name) stands for it"),
        "ProductInstanceUri": fixed(f"{product_uri}/{machine}", _S,
                                    "the product URI and the machine configuration's name"),
        "SoftwareRevision": plain("cnc_version_r", _S),
        "ProductCode": fixed(f"{vendor}-twin", _S, "the service's product"),
        "YearOfConstruction": fixed(datetime.now(UTC).year, _U16, "a twin is built when "
                                    "its service starts: the year of the start"),
    }


def machine_monitoring() -> dict[str, Source]:
    """MachineOperationMonitoringType's members (40501-1 8.4.2): the machine as channel 1
    shows it; PowerOnDuration is the kernel's running time in whole hours."""
    return {
        "OperationMode": plain("ch1.mc_active_mode_r", _I32, machine_operation_mode),
        "PowerOnDuration": plain("cnc_kernel_time_r", _U32,
                                 lambda s: int(s // SECONDS_PER_HOUR)),
    }


def channel_monitoring(c: int) -> dict[str, Source]:
    """ChannelMonitoringType's members (40501-1 8.4.4) for channel ``c``."""
    ch = f"ch{c}."
    return {
        "Name": fixed(f"Channel{c}", _S, "the channel's number"),
        "ChannelState": plain(ch + "mc_active_state_r", _I32, channel_state),
        "ChannelMode": plain(ch + "mc_active_mode_r", _I32, channel_mode),
        "FeedOverride": scaled(ch + "mc_active_feed_override_r", "0.1 %", OVERRIDE_RANGE),
        "RapidOverride": scaled(ch + "mc_active_rapid_override_r", "0.1 %", OVERRIDE_RANGE),
    }


def spindle_monitoring(c: int) -> dict[str, Source]:
    """SpindleMonitoringType's members (40501-1 8.4.6) for the spindle of channel ``c``."""
    ch = f"ch{c}."
    return {
        "Name": fixed(f"Spindle{c}", _S, "the spindle of channel c"),
        "IsRotating": plain(ch + "mc_spindle_active_rev_r", _B, lambda rev: rev != 0),
        "Override": scaled(ch + "mc_spindle_override_w", "0.1 %", OVERRIDE_RANGE),
    }


def active_program(c: int, state_ids: tuple[ua.NodeId, ...]) -> dict[str, Source]:
    """ProductionActiveProgramType's members (40501-1 9.3) for channel ``c``: the program
    of the channel; ``state_ids``: the state nodes of ProductionProgramStateMachineType,
    by number (CurrentState's Id)."""
    ch = f"ch{c}."
    objects = (ch + "mc_active_state_r", ch + "mc_active_program_name_r")

    def of_state(value: Callable[[int], Any], variant: ua.VariantType) -> Source:
        return derived(objects, lambda state, name: value(program_state(state, name)), variant)

    return {
        "Name": plain(ch + "mc_active_program_name_r", _S),
        "NumberInList": fixed(0, _U16, "the active program is not taken from a production "
                              "plan (40501-1 9.3: 0 without a list)"),
        "CurrentState": of_state(lambda k: ua.LocalizedText(PROGRAM_STATES[k], "en"),
                                 ua.VariantType.LocalizedText),
        "Id": of_state(lambda k: state_ids[k], ua.VariantType.NodeId),
        "Number": of_state(lambda k: k, _U32),
    }


def tool(c: int, i: int) -> dict[str, Source]:
    """ToolType's members (40501-1 8.5.3) for row ``i`` of channel ``c``'s tool list."""
    row = f"ch{c}.wz[{i}]."
    return {
        "Name": plain(row + "name", _S),
        "Identifier": fixed(f"T{i}", _S, "the tool list row: T<i>"),
        "ControlIdentifier1": fixed(i, _U32, "the tool list row: T<i>"),
        "ControlIdentifierInterpretation": fixed(0, _I32, "tools are named by number "
                                                 "(ToolManagement NumberBased)"),
        "Locked": derived((row + "valid", row + "life_expired"),
                          lambda valid, expired: not valid or expired, _B),
        "ReasonForLocking": derived((row + "valid", row + "life_expired"), _lock_reason, _S),
    }


def _lock_reason(valid: bool, expired: bool) -> str:
    if not valid:
        return "no tool data in this row (wz[i].valid FALSE)"
    return "tool life expired (life_used >= life_max)" if expired else ""


def tool_life(c: int, i: int) -> dict[str, Source]:
    """ToolLifeType's members (40501-1 8.5.5) of the cutting time of row ``i``: the value
    counts up to LimitValue (0: no limit)."""
    row = f"ch{c}.wz[{i}]."
    return {
        "CuttingTime": plain(row + "life_used", _D),
        "Indication": fixed(0, _I32, "cutting time (ToolLifeIndication Time)"),
        "IsCountingUp": fixed(True, _B, "life_used counts up"),
        "LimitValue": plain(row + "life_max", _D),
    }
