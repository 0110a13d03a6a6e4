"""Start, Hold, Reset and SelectProgram of a channel as OPC UA methods.

Neither OPC 40502 (CNC) nor OPC 40501-1 (MachineTool) declares a method that starts,
holds or resets a channel or a program (their channel and program types have variables
only), so these live in the twin's own namespace ``OBJECTS_URI`` under the machine node:
``Objects/Machines/<name>/CncObjects/Channel<c>/{Start, Hold, Reset, SelectProgram}``.

Each method writes the object the ``cnc`` CLI writes for the same command
(``ch<c>.mc_command_start_w`` ... , ``clients/channel_ops.py``) through
``Backend.decode_writes`` and ``apply_writes``, as the ADS and ZeroMQ front ends do, under
the role rule of every front end (``role_to_write`` of that object: a monitor gets
BadUserAccessDenied) and answers once the kernel applied or refused it
(docs/opcua.md, "Methods").
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Awaitable, Callable
from typing import Any

from asyncua import Node, Server, ua

from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.roles import role_to_write

from . import alarm_events_caller as caller
from .linked_backend import LinkedBackend
from .roles import role_of

log = logging.getLogger(__name__)

#: The twin's own namespace: what the companion specifications do not model.
OBJECTS_URI = "urn:cnc-objects:opcua"
_S = ua.StatusCodes
_E = AdsReturnCode
#: The ADS code of a refused command -> the OPC UA status of the Call.
CALL_STATUS: dict[int, int] = {
    _E.DEVICE_INVALIDDATA: _S.BadInvalidArgument,
    _E.DEVICE_INVALIDPARM: _S.BadInvalidArgument,
    _E.DEVICE_INVALIDSIZE: _S.BadInvalidArgument,
    _E.DEVICE_INVALIDACCESS: _S.BadUserAccessDenied,
    _E.DEVICE_NOTREADY: _S.BadInvalidState,
    _E.DEVICE_INVALIDSTATE: _S.BadInvalidState,
    _E.DEVICE_NOTFOUND: _S.BadNotFound,  # SelectProgram of a name not in the store
}
#: method -> (the channel object it writes, what it does)
COMMANDS: dict[str, tuple[str, str]] = {
    "Start": ("mc_command_start_w",
              "START: run the selected program, or resume after feedhold, M0/M1 or a "
              "single-block stop (cnc resume). BadInvalidState when the channel is not "
              "ready (in ERROR: Reset first)."),
    "Hold": ("mc_command_hold_w",
             "Feedhold: the path decelerates and stops (HOLD); Start resumes (cnc hold)."),
    "Reset": ("mc_command_reset_w",
              "RESET the channel from any state: ends the program, clears ERROR and its "
              "error list (cnc reset)."),
}
SELECT_OBJECT = "mc_command_program_name_w"
SELECT_HELP = ("Select the stored program Name for the next Start (AUTOMATIC), as "
               "cnc run does before its START.")

Callback = Callable[..., Awaitable[ua.StatusCode]]


class ChannelMethods:
    """The methods' callbacks over one ``Backend``."""

    def __init__(self, backend: LinkedBackend) -> None:
        self.backend = backend

    async def write(self, channel: int, name: str, value: Any) -> ua.StatusCode:
        """Write ``value`` to the object ``ch<channel>.<name>`` as the calling session may;
        Good once the kernel applied it, its refusal as a status code (nothing changed)."""
        entry = self.backend.space.by_name(f"ch{channel}.{name}")
        if entry is None or entry.write is None:
            return ua.StatusCode(_S.BadNotSupported)  # a catalog without this command
        obj = entry.obj
        role = role_of(caller.calling_user())
        if role is not None and not role.may(role_to_write(obj.port, obj.group)):
            return ua.StatusCode(_S.BadUserAccessDenied)
        try:
            data = obj.dtype.encode(value)
        except (ValueError, OverflowError, TypeError, UnicodeError):
            return ua.StatusCode(_S.BadInvalidArgument)
        code, message, items = self.backend.decode_writes(obj.port, obj.group, obj.offset, data)
        if not code:
            done: asyncio.Future[list[tuple[int, str]]] = (
                asyncio.get_running_loop().create_future())
            self.backend.apply_writes(items, done.set_result, holder=("opcua-methods", channel))
            code, message = next((r for r in await done if r[0]), (0, ""))
        if code:
            log.debug("OPC UA method writing %s refused: %s", obj.name, message)
            return ua.StatusCode(CALL_STATUS.get(code, _S.BadInternalError))
        return ua.StatusCode(_S.Good)

    def command(self, channel: int, name: str) -> Callback:
        """The callback of a method without arguments that writes TRUE to ``name``."""

        async def call(parent: ua.NodeId, *args: ua.Variant) -> ua.StatusCode:
            if args:
                return ua.StatusCode(_S.BadTooManyArguments)
            return await self.write(channel, name, True)

        return call

    def select(self, channel: int) -> Callback:
        """The callback of SelectProgram(Name)."""

        async def call(parent: ua.NodeId, *args: ua.Variant) -> ua.StatusCode:
            if not args:
                return ua.StatusCode(_S.BadArgumentsMissing)
            if len(args) > 1:
                return ua.StatusCode(_S.BadTooManyArguments)
            if args[0].VariantType != ua.VariantType.String or not isinstance(
                    args[0].Value, str):
                return ua.StatusCode(_S.BadTypeMismatch)
            if not args[0].Value.strip():
                return ua.StatusCode(_S.BadInvalidArgument)
            return await self.write(channel, SELECT_OBJECT, args[0].Value)

        return call


def _text(text: str) -> ua.LocalizedText:
    return ua.LocalizedText(text, "en")


async def _method(parent: Node, ns: int, path: str, name: str, callback: Callback,
                  description: str, inputs: list[ua.Argument]) -> Node:
    method = await parent.add_method(ua.NodeId(f"{path}.{name}", ns),
                                     ua.QualifiedName(name, ns), callback, inputs, [])
    await method.write_attribute(ua.AttributeIds.Description,
                                 ua.DataValue(ua.Variant(_text(description))))
    return method


async def build_channel_methods(server: Server, backend: LinkedBackend, machine: Node) -> Node:
    """``CncObjects`` (namespace ``OBJECTS_URI``) under ``machine`` with the methods of
    every channel; returns its node."""
    ns = await server.register_namespace(OBJECTS_URI)
    caller.install(server.iserver)  # the callbacks learn the caller's role
    methods = ChannelMethods(backend)
    root = await machine.add_object(ua.NodeId("CncObjects", ns),
                                    ua.QualifiedName("CncObjects", ns))
    await root.write_attribute(ua.AttributeIds.Description, ua.DataValue(ua.Variant(_text(
        "The twin's own commands, which OPC 40502 and 40501-1 do not model"))))
    name_argument = ua.Argument(Name="Name", DataType=ua.NodeId(ua.ObjectIds.String),
                                ValueRank=-1, ArrayDimensions=[],
                                Description=_text("A program in the store, e.g. part.nc"))
    for channel in backend.kernel.config.channels:
        c = channel.id
        path = f"CncObjects.Channel{c}"
        node = await root.add_object(ua.NodeId(path, ns), ua.QualifiedName(f"Channel{c}", ns))
        for name, (obj, description) in COMMANDS.items():
            await _method(node, ns, path, name, methods.command(c, obj), description, [])
        await _method(node, ns, path, "SelectProgram", methods.select(c), SELECT_HELP,
                      [name_argument])
    return root
